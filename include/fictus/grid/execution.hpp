#pragma once
// Where grid-level work runs: the number of threads (and, for a distributed run, the communicator
// that will join it). Made once from the options and passed to the objects that do the work.
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace fictus {

class Distribution;
/// The process's distribution (distribution.hpp): serial unless a program under mpirun set another.
std::shared_ptr<const Distribution> process_distribution();

/// Thrown when the interruption check of an Execution says stop (e.g. Ctrl-C in Python).
struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};

/// The threads a solve uses when solver.threads is 0: OMP_NUM_THREADS when it is set to a positive
/// number (its first entry), else the CPUs this process may run on (its affinity: all of the machine's,
/// or the cores mpirun or a batch system bound it to; at least 1).
int default_threads();

class Execution {
 public:
  /// threads ≥ 1, or 0 for default_threads() (the options' rule, options.hpp, caps it further).
  /// The distribution is the process's (serial unless a program under mpirun set another).
  explicit Execution(int threads = 1)
      : threads_(threads == 0 ? default_threads() : threads), distribution_(process_distribution()) {
    if (threads < 0) throw std::invalid_argument("solver.threads: must be >= 0, got " + std::to_string(threads));
  }
  int threads() const { return threads_; }
  /// Where the grid's vectors lie: one process, or slabs over MPI ranks (distribution.hpp).
  const Distribution& distribution() const { return *distribution_; }
  std::shared_ptr<const Distribution> shared_distribution() const { return distribution_; }

  /// A check for a request to stop, polled between the steps of a solve, in Newton and GMRES
  /// iterations and in the long assembly loops, always on the thread that called solve (OpenMP's
  /// thread 0). It returns true to stop; the work then ends with Interrupted. Once it has said stop,
  /// every later question is answered yes without asking it again (a check may say so only once, as
  /// Python's signal check does).
  void set_interrupt_check(std::function<bool()> check) { interrupt_check_ = std::move(check); }
  bool interrupt_requested() const {
    if (!interrupted_ && interrupt_check_ && interrupt_check_()) interrupted_ = true;
    return interrupted_;
  }
  void throw_if_interrupted() const {
    if (interrupt_requested()) throw Interrupted();
  }

  /// Told the name and duration of each step of a solve as it ends (on the calling thread), for
  /// progress lines on long runs.
  void set_progress(std::function<void(const std::string& phase, double seconds)> progress) {
    progress_ = std::move(progress);
  }
  void report(const std::string& phase, double seconds) const {
    if (progress_) progress_(phase, seconds);
  }

 private:
  int threads_;
  std::shared_ptr<const Distribution> distribution_;
  std::function<bool()> interrupt_check_;
  mutable bool interrupted_ = false;  // asked and answered on the calling thread only
  std::function<void(const std::string&, double)> progress_;
};

}  // namespace fictus
