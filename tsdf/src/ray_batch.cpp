#include "featsense/tsdf/ray_batch.hpp"

#include <algorithm>
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
    const uint16_t largest = *std::max_element(rays.origin_index.begin(), rays.origin_index.end());
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
