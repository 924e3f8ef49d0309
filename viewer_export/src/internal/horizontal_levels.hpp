#pragma once
// The heights at which a mesh has most of its floor and of its ceiling, from a histogram of
// its horizontal faces: what the plan view cuts at when no path says where the sensor was.

#include <optional>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::viewer_export {

struct HorizontalLevels {
  std::optional<double> floor_m;    ///< the most upward-facing area, map frame z
  std::optional<double> ceiling_m;  ///< the most downward-facing area a storey above the floor
};

/// Floors face up and ceilings down (the mesh's normals where it has them, else its winding:
/// counter-clockwise seen from the free side). A ceiling counts only from 1.8 m above the floor
/// (the undersides of tables do not) and with at least a tenth of the floor's area.
HorizontalLevels find_horizontal_levels(const mesh::TriangleMesh& mesh);

}  // namespace featsense::viewer_export
