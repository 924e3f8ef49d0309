#pragma once
/// A coarser mesh for display: vertices merged on a uniform grid (vertex clustering).
///
/// Edge collapse (mesh_cleanup.hpp) keeps the surface more faithfully but takes minutes for
/// millions of triangles and drops per-vertex layers; a viewer needs a mesh under its triangle
/// budget in about a second, with each kept vertex traceable to the vertices it stands for so
/// that their layers (error, navigation cost) can be averaged onto it.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh {

struct ClusteredMesh {
  TriangleMesh mesh;  ///< vertices: the mean of each cluster; no normals, no parts
  /// For each vertex of the input, the vertex of `mesh` it was merged into.
  std::vector<uint32_t> cluster_of_vertex;
  double cell_size_m = 0.0;  ///< the grid's cell, metres (0: the input was kept as it is)
};

/// Merges the vertices of `mesh` per grid cell, with the cell grown until at most
/// `max_triangles` triangles are left (triangles whose corners fall into fewer than three
/// cells vanish, and repeated ones are kept once). A mesh already within the budget comes back
/// unchanged (cell_size_m 0). Throws MeshError for an invalid mesh or a budget of 0.
ClusteredMesh cluster_vertices(const TriangleMesh& mesh, std::size_t max_triangles);

/// The mean of `values` (one per input vertex) over each cluster, ignoring values that are not
/// numbers; a cluster with none is NaN.
std::vector<float> average_per_cluster(const ClusteredMesh& clustered,
                                       const std::vector<float>& values);

}  // namespace featsense::mesh
