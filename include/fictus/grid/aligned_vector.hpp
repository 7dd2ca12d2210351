#pragma once
// std::vector with 64-byte aligned storage: every grid array has the alignment the fast transforms
// (and SIMD loops) want, whatever allocated it. Plans made on one aligned array run on any other.
#include <cstddef>
#include <new>
#include <vector>

namespace fictus {

namespace detail {
inline constexpr std::size_t grid_alignment = 64;
/// Aligned storage; large blocks are advised to use transparent huge pages (cheaper first touch).
void* aligned_allocate(std::size_t bytes);
void aligned_free(void* p) noexcept;
}  // namespace detail

template <class T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(detail::aligned_allocate(n * sizeof(T))); }
  void deallocate(T* p, std::size_t) noexcept { detail::aligned_free(p); }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

}  // namespace fictus
