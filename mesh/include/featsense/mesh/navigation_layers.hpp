#pragma once
/// Per-vertex traversability layers of a ground mesh, for mesh-based navigation.
///
/// The mesh is in the map frame (metres, Z up). Each layer is a plain array with one value per
/// vertex; lethal faces are those with a lethal vertex.

#include <cstdint>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh {

struct NavigationSettings {
  double max_slope_deg = 20.0;  ///< steeper than this is lethal, degrees from up
  double max_step_m = 0.15;     ///< a larger height difference within the radius is lethal
  double radius_m = 0.3;        ///< neighbourhood of roughness and height difference
};

struct NavigationLayers {
  std::vector<float> inclination_deg;  ///< angle of the vertex normal from +Z, degrees
  std::vector<float> roughness_deg;    ///< mean angle of neighbour normals from the mean
  std::vector<float> height_diff_m;    ///< max - min Z of vertices within the radius (3D)
  std::vector<float> cost;             ///< [0, 1], 1 = lethal
  std::vector<uint8_t> lethal_faces;   ///< per triangle, 1 where any vertex is lethal
};

/// Unit vertex normals: the mesh's own where it has them, else area-weighted face normals.
/// Throws MeshError for an empty or invalid mesh.
std::vector<Eigen::Vector3f> vertex_normals(const TriangleMesh& mesh);

/// Computes the layers; neighbourhoods come from a uniform grid of cell size `radius_m`
/// (linear in the vertex count). Throws MeshError for an empty or invalid mesh or settings
/// that are not positive.
NavigationLayers compute_navigation_layers(const TriangleMesh& mesh,
                                           const NavigationSettings& settings = {});

}  // namespace featsense::mesh
