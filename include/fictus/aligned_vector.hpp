#pragma once
// std::vector with storage from the FFTW allocator, so that every grid array has the alignment
// the FFTW plans were made for (plans are created once and executed on many arrays).
#include <cstddef>
#include <new>
#include <vector>

namespace fictus {

namespace detail {
void* fftw_aligned_malloc(std::size_t bytes);
void fftw_aligned_free(void* p) noexcept;
}  // namespace detail

template <class T>
struct FftwAllocator {
  using value_type = T;
  FftwAllocator() = default;
  template <class U>
  FftwAllocator(const FftwAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    void* p = detail::fftw_aligned_malloc(n * sizeof(T));
    if (p == nullptr && n != 0) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { detail::fftw_aligned_free(p); }
  template <class U>
  bool operator==(const FftwAllocator<U>&) const noexcept { return true; }
};

template <class T>
using AlignedVector = std::vector<T, FftwAllocator<T>>;

}  // namespace fictus
