#include "fictus/io/process.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "fictus/solve/fictitious_domain_solver.hpp"

namespace fictus {

namespace {

/// The value of the line "<key> <n> kB" of a /proc file, in bytes (0 where there is none).
std::size_t proc_kib(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::size_t(std::stoull(line.substr(key.size()))) * 1024;
  return 0;
}

}  // namespace

std::size_t peak_memory_bytes() { return proc_kib("/proc/self/status", "VmHWM:"); }

bool reset_peak_memory() {
  std::ofstream out("/proc/self/clear_refs");
  return bool(out << "5" << std::flush);
}

std::size_t available_memory_bytes() { return proc_kib("/proc/meminfo", "MemAvailable:"); }

template <int dim>
void check_memory(const BasicProblem<dim>& problem, const SolverOptions& options) {
  const double gib = double(1 << 30);
  const double need = double(estimated_peak_bytes(problem, options));
  const double limit = options.max_memory > 0 ? options.max_memory * gib : double(available_memory_bytes());
  if (limit <= 0 || need <= limit) return;
  char line[320];
  std::snprintf(line, sizeof line,
                "%s: N = %d needs about %.3g GiB, more than the %.3g GiB %s (a smaller N, or solver.max_memory)",
                options.max_memory > 0 ? "solver.max_memory" : "domain.N", problem.N, need / gib, limit / gib,
                options.max_memory > 0 ? "of solver.max_memory" : "available");
  throw std::invalid_argument(line);
}

template void check_memory(const BasicProblem<2>&, const SolverOptions&);
template void check_memory(const BasicProblem<3>&, const SolverOptions&);

}  // namespace fictus
