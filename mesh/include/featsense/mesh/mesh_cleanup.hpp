#pragma once
/// Cleaning a mesh for use elsewhere: small floating components (noise) removed,
/// non-manifold vertices and edges split so that half-edge structures accept the mesh, holes
/// up to a size filled, and an optional simplification whose error is measured.

#include <cstddef>
#include <functional>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh {

struct CleanupSettings {
  /// Connected components with less area than this are removed, square metres (0 = keep).
  double min_component_area_m2 = 0.0;
  /// Connected components with fewer triangles than this are removed (0 = keep).
  std::size_t min_component_triangles = 0;
  /// Split vertices and edges where the surface is not a manifold. When false, such a mesh is
  /// an error.
  bool fix_non_manifold = true;
  /// Holes whose border is at most this long are filled, metres (0 = none).
  double max_hole_perimeter_m = 0.0;
  /// Fraction of the triangles kept by edge collapse, in (0, 1]; 1 = no simplification.
  /// Borders are kept in place.
  double simplify_ratio = 1.0;
  /// Count self-intersecting triangle pairs of the result (costs about as much as the rest).
  bool check_self_intersections = true;
  /// Where given: true for a point on a cut of a larger mesh that this one is a piece of (a
  /// tile's border). A component that reaches a cut is kept whatever its size, since the rest
  /// of it lies beyond; a border that passes a cut is not a hole, it is the cut; and cut edges
  /// are borders, which simplification keeps in place. So pieces cleaned apart still meet.
  std::function<bool(const Eigen::Vector3f&)> on_cut;
};

struct CleanupReport {
  std::size_t input_vertices = 0;
  std::size_t input_triangles = 0;
  std::size_t output_vertices = 0;
  std::size_t output_triangles = 0;
  std::size_t degenerate_triangles_removed = 0;  ///< repeated or merged vertices, duplicates
  std::size_t removed_components = 0;
  std::size_t removed_component_triangles = 0;
  std::size_t non_manifold_vertices_fixed = 0;  ///< vertices split (also at non-manifold edges)
  std::size_t holes_filled = 0;
  std::size_t holes_left = 0;               ///< borders longer than the limit (or not fillable)
  std::size_t borders_on_cuts = 0;          ///< borders left alone since they pass a cut
  std::size_t components_kept_on_cuts = 0;  ///< small, but reaching a cut
  /// Distance between the simplified surface and the mesh before simplification, both ways
  /// (vertices and surface samples), metres; 0 without simplification.
  double simplification_max_error_m = 0.0;
  double simplification_mean_error_m = 0.0;
  std::size_t border_edges = 0;        ///< of the result
  bool is_closed = false;              ///< no border edges
  bool is_manifold = false;            ///< every vertex and edge of the result is manifold
  bool is_valid = false;               ///< CGAL's is_valid_polygon_mesh of the result
  std::size_t self_intersections = 0;  ///< triangle pairs (when checked)
  double seconds = 0.0;
};

/// Cleans `mesh` in place. Vertex normals, where the input has them, stay those of the input
/// unless hole filling or simplification changed the surface; then they are recomputed
/// (area-weighted face normals). Throws MeshError for an invalid mesh or settings, and for a
/// non-manifold mesh when fix_non_manifold is false.
CleanupReport clean_mesh(TriangleMesh& mesh, const CleanupSettings& settings);

}  // namespace featsense::mesh
