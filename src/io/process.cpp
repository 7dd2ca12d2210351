#include "fictus/io/process.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "fictus/fictitious_domain_solver.hpp"

namespace fictus {

std::size_t peak_memory_bytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::size_t(std::stoull(line.substr(6))) * 1024;
  return 0;
}

std::size_t available_memory_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string line;
  while (std::getline(meminfo, line))
    if (line.rfind("MemAvailable:", 0) == 0) return std::size_t(std::stoull(line.substr(13))) * 1024;
  return 0;
}

void check_memory(const Problem& problem, const SolverOptions& options) {
  const double gib = double(1 << 30);
  const double need = double(estimated_peak_bytes(problem, options));
  const double limit = options.max_memory > 0 ? options.max_memory * gib : double(available_memory_bytes());
  if (limit <= 0 || need <= limit) return;
  char line[320];
  std::snprintf(line, sizeof line,
                "domain.N: N = %d needs about %.3g GiB, more than the %.3g GiB %s (a smaller N, or solver.max_memory)",
                problem.N, need / gib, limit / gib, options.max_memory > 0 ? "of solver.max_memory" : "available");
  throw std::invalid_argument(line);
}

}  // namespace fictus
