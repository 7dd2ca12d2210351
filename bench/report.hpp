#pragma once
// What both benchmark programs write beside their figures: printf-style text, a shell command's
// output (the commit, the host), and the machine line.
#include <unistd.h>

#include <cstdio>
#include <string>

namespace bench {

inline std::string format(const char* f, auto... args) {
  char buffer[1024];
  std::snprintf(buffer, sizeof buffer, f, args...);
  return buffer;
}

inline std::string command_output(const char* command) {
  std::string out;
  if (FILE* p = popen(command, "r")) {
    char buffer[256];
    while (std::fgets(buffer, sizeof buffer, p)) out += buffer;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out.empty() ? "unknown" : out;
}

/// CPU model, cores and memory of this machine.
inline std::string machine() {
  return format("%s, %ld cores, %.0f GiB",
                command_output("sed -n 's/^model name\\s*: //p' /proc/cpuinfo | head -1").c_str(),
                sysconf(_SC_NPROCESSORS_ONLN), sysconf(_SC_PHYS_PAGES) * double(sysconf(_SC_PAGESIZE)) / (1 << 30));
}

}  // namespace bench
