#pragma once
// An allocator for the CPU integrator's large arrays (the map, the candidates, the bits: up to
// hundreds of MB, touched brick by brick all over): 2 MB-aligned and, on Linux, backed by
// transparent huge pages where the system allows them on request (the common "madvise"
// setting). A walk or the fusion then finds most addresses in the TLB instead of walking the
// page tables for every brick it enters.

#include <cstddef>
#include <cstdlib>
#include <limits>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace featsense::tsdf::detail {

template <typename T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t{2} << 20;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}  // NOLINT(google-explicit-constructor)

  T* allocate(size_t count) {
    if (count > std::numeric_limits<size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
    const size_t bytes = count * sizeof(T);
    if (bytes < kHugePage) return static_cast<T*>(::operator new(bytes));
    // Whole huge pages, so that the last one is not shared with other data.
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* block = std::aligned_alloc(kHugePage, rounded);
    if (block == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(block, rounded, MADV_HUGEPAGE);  // a hint: without it, ordinary pages
#endif
    return static_cast<T*>(block);
  }

  void deallocate(T* data, size_t count) noexcept {
    if (count * sizeof(T) < kHugePage) {
      ::operator delete(data);
    } else {
      std::free(data);
    }
  }

  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
  template <typename U>
  bool operator!=(const HugePageAllocator<U>&) const noexcept {
    return false;
  }
};

}  // namespace featsense::tsdf::detail
