#pragma once
// What the operating system says about this process (Linux /proc), for reports.
#include <cstddef>

namespace fictus {

/// Peak resident memory of this process in bytes (VmHWM; 0 where unknown).
std::size_t peak_memory_bytes();

}  // namespace fictus
