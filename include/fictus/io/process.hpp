#pragma once
// What the operating system says about this process (Linux /proc), for reports.
#include <cstddef>

#include "fictus/solve/problem.hpp"

namespace fictus {

/// Peak resident memory of this process in bytes (VmHWM; 0 where unknown).
std::size_t peak_memory_bytes();

/// Starts the peak over from the present resident memory (writes 5 to /proc/self/clear_refs), so that
/// one process can measure several runs; false where the system does not allow it.
bool reset_peak_memory();

/// Memory the system can give without swapping (MemAvailable; 0 where unknown).
std::size_t available_memory_bytes();

/// Refuses a solve whose estimated peak (estimated_peak_bytes) exceeds options.max_memory GiB (throws
/// std::invalid_argument naming solver.max_memory), or the available memory when that is 0 (naming
/// domain.N), with the estimate and the limit. Call it before the solver is made.
template <int dim>
void check_memory(const BasicProblem<dim>& problem, const SolverOptions& options);

}  // namespace fictus
