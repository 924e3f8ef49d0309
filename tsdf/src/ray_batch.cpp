#include "featsense/tsdf/ray_batch.hpp"

#include <stdexcept>
#include <string>

namespace featsense::tsdf {

void check_ray_batch(const RayBatch& rays) {
  if (!rays.interpolate.empty() && rays.interpolate.size() != rays.endpoints_m.size()) {
    throw std::invalid_argument("TSDF rays: " + std::to_string(rays.interpolate.size()) +
                                " interpolation flags for " +
                                std::to_string(rays.endpoints_m.size()) + " end points");
  }
  if (!rays.carving_level.empty() && rays.carving_level.size() != rays.endpoints_m.size()) {
    throw std::invalid_argument("TSDF rays: " + std::to_string(rays.carving_level.size()) +
                                " carving levels for " + std::to_string(rays.endpoints_m.size()) +
                                " end points");
  }
  if (!rays.origin_index.empty()) {
    if (rays.origin_index.size() != rays.endpoints_m.size()) {
      throw std::invalid_argument("TSDF rays: " + std::to_string(rays.origin_index.size()) +
                                  " origin indices for " + std::to_string(rays.endpoints_m.size()) +
                                  " end points");
    }
    // In blocks of a fixed length, which the compiler vectorizes (std::max_element and a loop
    // of unknown length are not: 70 against 9 us for an OS1-128 scan, which is on the GPU
    // path's critical path); the rest one by one.
    constexpr size_t kBlock = 64;
    const uint16_t* index = rays.origin_index.data();
    const size_t n = rays.origin_index.size();
    uint16_t largest = 0;
    size_t i = 0;
    for (; i + kBlock <= n; i += kBlock) {
      uint16_t block = 0;
      for (size_t k = 0; k < kBlock; ++k) block = index[i + k] > block ? index[i + k] : block;
      largest = block > largest ? block : largest;
    }
    for (; i < n; ++i) largest = index[i] > largest ? index[i] : largest;
    if (largest >= rays.origins_m.size()) {
      throw std::invalid_argument("TSDF rays: origin index " + std::to_string(largest) + " of " +
                                  std::to_string(rays.origins_m.size()) + " origins");
    }
    return;
  }
  if (rays.origins_m.size() == 1 || rays.origins_m.size() == rays.endpoints_m.size()) return;
  if (rays.endpoints_m.empty() && rays.origins_m.empty()) return;
  throw std::invalid_argument("TSDF rays: " + std::to_string(rays.origins_m.size()) +
                              " origins for " + std::to_string(rays.endpoints_m.size()) +
                              " end points; give one origin or one per end point");
}

}  // namespace featsense::tsdf
