#pragma once
/// Host memory for the arrays of a scan's rays (RayBatch): page-locked once a CUDA integrator
/// exists in the process, so that the GPU reads them by DMA straight from where they were
/// written, without a copy into a staging buffer first (that copy took a third of a scan's
/// time on the GPU path). Page-locked blocks are pooled: a run builds a new RayBatch for every
/// scan, and locking fresh memory takes milliseconds. Before page locking is enabled, and in
/// builds or on machines without CUDA, the memory is ordinary heap memory.

#include <cstddef>
#include <limits>
#include <new>
#include <vector>

namespace featsense::tsdf {

namespace host_memory {

/// Allocates and frees page-locked memory (the CUDA runtime's): allocate returns nullptr on
/// failure.
struct PageLocking {
  void* (*allocate)(size_t bytes) = nullptr;
  void (*release)(void* block) = nullptr;
};

/// From now on, blocks come from page-locked memory where it can be had. Called by the CUDA
/// backend when it makes an integrator; later calls change nothing.
void enable_page_locking(PageLocking locking);
/// Whether `data` is the start of a page-locked block of this pool (a RayBatch array).
bool is_page_locked(const void* data);

void* allocate(size_t bytes);
void deallocate(void* data, size_t bytes) noexcept;

/// Free page-locked bytes the pool keeps for reuse (beyond them, freed blocks are unlocked).
constexpr size_t kMaxCachedBytes = size_t{256} << 20;

}  // namespace host_memory

/// A standard allocator on host_memory.
template <typename T>
struct HostAllocator {
  using value_type = T;
  HostAllocator() = default;
  template <typename U>
  HostAllocator(const HostAllocator<U>&) noexcept {}  // NOLINT(google-explicit-constructor)

  T* allocate(size_t count) {
    if (count > std::numeric_limits<size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(host_memory::allocate(count * sizeof(T)));
  }
  void deallocate(T* data, size_t count) noexcept {
    host_memory::deallocate(data, count * sizeof(T));
  }
  template <typename U>
  bool operator==(const HostAllocator<U>&) const noexcept {
    return true;
  }
  template <typename U>
  bool operator!=(const HostAllocator<U>&) const noexcept {
    return false;
  }
};

template <typename T>
using HostVector = std::vector<T, HostAllocator<T>>;

}  // namespace featsense::tsdf
