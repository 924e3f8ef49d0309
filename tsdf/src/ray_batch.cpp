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
  if (rays.origins_m.size() == 1 || rays.origins_m.size() == rays.endpoints_m.size()) return;
  if (rays.endpoints_m.empty() && rays.origins_m.empty()) return;
  throw std::invalid_argument("TSDF rays: " + std::to_string(rays.origins_m.size()) +
                              " origins for " + std::to_string(rays.endpoints_m.size()) +
                              " end points; give one origin or one per end point");
}

}  // namespace featsense::tsdf
