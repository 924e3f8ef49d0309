#include "featsense/tsdf/host_memory.hpp"

#include <map>
#include <mutex>
#include <unordered_map>

namespace featsense::tsdf::host_memory {
namespace {

/// Arrays smaller than this stay on the heap: their copy costs less than locking pages.
constexpr size_t kMinLockedBytes = size_t{64} << 10;
constexpr size_t kLockGranule = size_t{64} << 10;

struct Pool {
  std::mutex mutex;
  PageLocking locking;
  bool enabled = false;
  std::unordered_map<const void*, size_t> capacity;  ///< every page-locked block: its bytes
  std::multimap<size_t, void*> free_blocks;          ///< blocks to reuse, by bytes
  size_t free_bytes = 0;
};

/// Never destroyed: vectors freed during static destruction still find their blocks.
Pool& pool() {
  static Pool* const instance = new Pool;
  return *instance;
}

}  // namespace

void enable_page_locking(PageLocking locking) {
  Pool& p = pool();
  const std::lock_guard<std::mutex> lock(p.mutex);
  if (p.enabled || locking.allocate == nullptr || locking.release == nullptr) return;
  p.locking = locking;
  p.enabled = true;
}

bool is_page_locked(const void* data) {
  Pool& p = pool();
  const std::lock_guard<std::mutex> lock(p.mutex);
  return p.capacity.count(data) != 0;
}

void* allocate(size_t bytes) {
  Pool& p = pool();
  if (bytes >= kMinLockedBytes) {
    const std::lock_guard<std::mutex> lock(p.mutex);
    if (p.enabled) {
      // A cached block at most twice the size asked for, so that small arrays do not hold
      // on to large blocks.
      const auto reuse = p.free_blocks.lower_bound(bytes);
      if (reuse != p.free_blocks.end() && reuse->first / 2 <= bytes) {
        void* block = reuse->second;
        p.free_bytes -= reuse->first;
        p.free_blocks.erase(reuse);
        return block;
      }
      // A quarter more than asked: the next scan may have a few more points.
      const size_t size = (bytes + bytes / 4 + kLockGranule - 1) / kLockGranule * kLockGranule;
      if (void* block = p.locking.allocate(size)) {
        p.capacity.emplace(block, size);
        return block;
      }
    }
  }
  return ::operator new(bytes);
}

void deallocate(void* data, size_t /*bytes*/) noexcept {
  if (data == nullptr) return;
  Pool& p = pool();
  {
    const std::lock_guard<std::mutex> lock(p.mutex);
    const auto found = p.capacity.find(data);
    if (found != p.capacity.end()) {
      const size_t size = found->second;
      if (p.free_bytes + size <= kMaxCachedBytes) {
        p.free_blocks.emplace(size, data);
        p.free_bytes += size;
      } else {
        p.capacity.erase(found);
        p.locking.release(data);
      }
      return;
    }
  }
  ::operator delete(data);
}

}  // namespace featsense::tsdf::host_memory
