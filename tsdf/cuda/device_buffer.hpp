#pragma once
// Device memory that grows but never shrinks, so a steady stream of scans allocates nothing.

#include <cuda_runtime.h>

#include <cstddef>

#include "cuda_check.hpp"

namespace featsense::tsdf::cuda {

template <typename T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  explicit DeviceBuffer(size_t count) { reserve(count); }
  ~DeviceBuffer() { cudaFree(data_); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;

  /// Makes room for `count` elements (the old contents are dropped when it grows).
  void reserve(size_t count) {
    if (count <= capacity_) return;
    FEATSENSE_CUDA_CHECK(cudaFree(data_));
    data_ = nullptr;
    capacity_ = 0;
    FEATSENSE_CUDA_CHECK(cudaMalloc(reinterpret_cast<void**>(&data_), count * sizeof(T)));
    capacity_ = count;
  }
  /// reserve() with room for a quarter more: for per-scan buffers, so that the point counts
  /// of a recording, which vary from scan to scan, seldom reallocate.
  void grow(size_t count) {
    if (count > capacity_) reserve(count + count / 4);
  }
  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t capacity() const { return capacity_; }
  size_t bytes() const { return capacity_ * sizeof(T); }

 private:
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

/// Page-locked host memory, so uploads run asynchronously at full speed.
template <typename T>
class PinnedBuffer {
 public:
  PinnedBuffer() = default;
  ~PinnedBuffer() { cudaFreeHost(data_); }
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;

  void reserve(size_t count) {
    if (count <= capacity_) return;
    FEATSENSE_CUDA_CHECK(cudaFreeHost(data_));
    data_ = nullptr;
    capacity_ = 0;
    FEATSENSE_CUDA_CHECK(cudaMallocHost(reinterpret_cast<void**>(&data_), count * sizeof(T)));
    capacity_ = count;
  }
  /// As DeviceBuffer::grow (a page-locked allocation takes milliseconds).
  void grow(size_t count) {
    if (count > capacity_) reserve(count + count / 4);
  }
  T* data() { return data_; }

 private:
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

}  // namespace featsense::tsdf::cuda
