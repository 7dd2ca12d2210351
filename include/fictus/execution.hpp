#pragma once
// Where grid-level work runs: the number of threads (and, for a distributed run, the communicator
// that will join it). Made once from the options and passed to the objects that do the work.
#include <stdexcept>
#include <string>

namespace fictus {

class Execution {
 public:
  /// threads ≥ 1 (the options' rule, options.hpp, caps it further).
  explicit Execution(int threads = 1) : threads_(threads) {
    if (threads < 1) throw std::invalid_argument("solver.threads: must be >= 1, got " + std::to_string(threads));
  }
  int threads() const { return threads_; }

 private:
  int threads_;
};

}  // namespace fictus
