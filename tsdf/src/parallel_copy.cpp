#include "parallel_copy.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstring>

namespace featsense::tsdf::detail {

void parallel_copy(void* destination, const void* source, size_t bytes) {
  constexpr size_t kBlock = 256 * 1024;  // large enough that a block outweighs its scheduling
  auto* to = static_cast<unsigned char*>(destination);
  const auto* from = static_cast<const unsigned char*>(source);
  if (bytes <= kBlock) {
    std::memcpy(to, from, bytes);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, (bytes + kBlock - 1) / kBlock, 1),
                    [&](const tbb::blocked_range<size_t>& blocks) {
                      for (size_t b = blocks.begin(); b != blocks.end(); ++b) {
                        const size_t offset = b * kBlock;
                        const size_t size = offset + kBlock <= bytes ? kBlock : bytes - offset;
                        std::memcpy(to + offset, from + offset, size);
                      }
                    });
}

}  // namespace featsense::tsdf::detail
