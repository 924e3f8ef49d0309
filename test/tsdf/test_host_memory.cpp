// The pool behind RayBatch's arrays (tsdf/host_memory.hpp), with a stand-in for the CUDA
// runtime's page locking that counts what it is asked to do. Page locking is process-wide,
// so this file is a test program of its own.

#include <gtest/gtest.h>

#include <cstdlib>
#include <set>

#include "featsense/tsdf/host_memory.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::tsdf {
namespace {

std::set<void*> locked_blocks;
int lock_calls = 0;
int release_calls = 0;

void* lock(size_t bytes) {
  ++lock_calls;
  void* block = std::malloc(bytes);
  locked_blocks.insert(block);
  return block;
}

void release(void* block) {
  ++release_calls;
  locked_blocks.erase(block);
  std::free(block);
}

constexpr size_t kScanPoints = 131072;  // an OS1-128 scan

TEST(HostMemory, PoolsPageLockedBlocksForLargeArraysOnceEnabled) {
  {
    RayBatch before;
    before.endpoints_m.resize(kScanPoints);
    EXPECT_FALSE(host_memory::is_page_locked(before.endpoints_m.data()))
        << "no page locking before a CUDA integrator enables it";
  }
  host_memory::enable_page_locking({&lock, &release});

  const void* first_block = nullptr;
  {
    RayBatch rays;
    rays.endpoints_m.resize(kScanPoints);
    rays.interpolate.resize(16);  // too small to be worth locking
    EXPECT_TRUE(host_memory::is_page_locked(rays.endpoints_m.data()));
    EXPECT_EQ(locked_blocks.count(rays.endpoints_m.data()), 1u);
    EXPECT_FALSE(host_memory::is_page_locked(rays.interpolate.data()));
    first_block = rays.endpoints_m.data();
    EXPECT_EQ(lock_calls, 1);
  }
  // The next scan, a few points more, reuses the freed block instead of locking new memory.
  RayBatch next;
  next.endpoints_m.resize(kScanPoints + 1000);
  EXPECT_EQ(next.endpoints_m.data(), first_block);
  EXPECT_EQ(lock_calls, 1);
  // A small array does not take a large cached block.
  {
    RayBatch large;
    large.endpoints_m.resize(8 * kScanPoints);
  }
  HostVector<uint8_t> small(100000);
  EXPECT_EQ(lock_calls, 3);
  EXPECT_EQ(release_calls, 0);
}

TEST(HostMemory, KeepsAtMostItsCapOfFreeBlocks) {
  host_memory::enable_page_locking({&lock, &release});
  const int releases_before = release_calls;
  {
    std::vector<HostVector<char>> arrays(24);
    for (HostVector<char>& array : arrays) array.reserve(size_t{16} << 20);
  }
  // 24 blocks of 20 MB (a quarter more than asked) were freed; at most 256 MB stay cached.
  EXPECT_GE(release_calls - releases_before,
            24 - static_cast<int>(host_memory::kMaxCachedBytes / (size_t{20} << 20)));
  for (void* block : locked_blocks) EXPECT_TRUE(host_memory::is_page_locked(block));
}

}  // namespace
}  // namespace featsense::tsdf
