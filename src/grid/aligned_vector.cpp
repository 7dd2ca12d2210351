#include "fictus/grid/aligned_vector.hpp"

#include <sys/mman.h>

#include <cstdint>

namespace fictus::detail {

void* aligned_allocate(std::size_t bytes) {
  void* p = ::operator new(bytes == 0 ? grid_alignment : bytes, std::align_val_t(grid_alignment));
  // Grid arrays are touched once in full: ask for transparent huge pages, which makes their first
  // touch (page faults) markedly cheaper. Advisory only; ignored where THP is off.
  constexpr std::size_t large = std::size_t(8) << 20, page = 4096;
  if (bytes >= large) {
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(p) + page - 1) & ~(page - 1);
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(page - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
  return p;
}

void aligned_free(void* p) noexcept { ::operator delete(p, std::align_val_t(grid_alignment)); }

}  // namespace fictus::detail
