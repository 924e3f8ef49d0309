#pragma once
// The first step of the plan view: per pixel, the highest surface of the mesh below the cut.

#include <cstdint>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "internal/cut_height_field.hpp"
#include "internal/plan_frame.hpp"

namespace featsense::viewer_export {

struct PlanSurface {
  std::vector<float> height_m;  ///< per pixel, map frame z; NaN: nothing below the cut
  /// Per pixel, how brightly the surface seen faces a light from the upper left (north-west,
  /// 45 degrees up): 0 (away) to 255 (towards it); a flat floor has kFlatLight.
  std::vector<uint8_t> light;
  std::vector<uint8_t> is_wall;  ///< 1 where the surface seen is steep (a wall, an object's side)
  /// Per pixel, the index of the triangle seen (-1: none), for colours carried by the mesh's
  /// vertices rather than by heights.
  std::vector<int32_t> triangle;
  static constexpr uint8_t kFlatLight = 180;
};

/// Rasterizes every triangle once (no pixel-by-triangle search). Steep triangles, which from
/// above are slivers thinner than a pixel, cover every pixel their outline touches, at their
/// highest point below the cut: walls cut by the plan become unbroken lines.
PlanSurface rasterize_below_cut(const mesh::TriangleMesh& mesh, const PlanFrame& frame,
                                const CutHeightField& cut);

}  // namespace featsense::viewer_export
