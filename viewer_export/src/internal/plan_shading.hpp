#pragma once
// The plan's colours: floors by height (a light ramp, so that lines and paths stand out) and
// hill-shaded, walls and the sides of objects dark, steps between surfaces outlined.

#include <array>
#include <cstdint>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "internal/plan_frame.hpp"
#include "internal/plan_surface.hpp"

namespace featsense::viewer_export {

struct HeightRange {
  double low_m = 0.0;   ///< the first colour of the ramp
  double high_m = 1.0;  ///< the last
};

/// The 2nd to 98th percentile of the level surfaces seen, at least a metre apart (a flat floor
/// gets the ramp's first colours, not all of it).
HeightRange colour_range(const PlanSurface& surface);

/// The ramp's colour at t in [0, 1]: pale blue, green, yellow, orange, terracotta.
std::array<uint8_t, 3> height_colour(double t);

/// RGBA rows from the top; pixels with nothing are an opaque off-white, so that the grid and
/// the text read in any viewer.
std::vector<uint8_t> shade_plan(const PlanSurface& surface, const PlanFrame& frame,
                                const HeightRange& range);

/// As shade_plan, with each surface in the mean colour of its triangle's vertices
/// (`vertex_rgb`, one per vertex of `mesh`) instead of its height's. Walls are not widened:
/// their own colour is what they show, and widening would paint the floor beside them.
std::vector<uint8_t> shade_plan_by_vertex(
    const PlanSurface& surface, const PlanFrame& frame, const mesh::TriangleMesh& mesh,
    const std::vector<Eigen::Matrix<uint8_t, 3, 1>>& vertex_rgb);

}  // namespace featsense::viewer_export
