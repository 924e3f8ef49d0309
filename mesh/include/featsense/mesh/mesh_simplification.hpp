#pragma once
/// Coarser meshes for levels of detail: edge collapse by meshoptimizer's quadric simplifier,
/// with chosen vertices held (a tile's cut, so that neighbouring tiles simplified alike still
/// meet), and tiles joined along their cuts.

#include <cstddef>
#include <limits>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh {

struct SimplifySettings {
  /// Share of the triangles to keep, in (0, 1]; fewer survive where the error bound stops the
  /// collapses first.
  double target_ratio = 0.25;
  /// No collapse that moves the surface further than this, metres.
  double max_error_m = std::numeric_limits<double>::infinity();
};

struct SimplifiedMesh {
  TriangleMesh mesh;   ///< only the vertices still used; normals kept where the input had them
  double error_m = 0;  ///< the simplifier's estimate of the largest deviation, metres
};

/// Throws std::invalid_argument for a ratio outside (0, 1], a negative error bound, or `held`
/// of another length than the vertices. The surviving vertices keep their positions and
/// normals; parts are dropped. Vertices marked in `held` (empty: none) are neither moved nor
/// removed: the edges between held vertices stay as they are, so two tiles whose shared cut is
/// held in both still meet exactly. Other open borders (holes) are simplified along themselves.
SimplifiedMesh simplify_mesh(const TriangleMesh& mesh, const SimplifySettings& settings,
                             const std::vector<bool>& held = {});

/// The meshes as one, with the vertices that lie at exactly the same position (the shared
/// border of two tiles) merged. Normals are kept where every part with vertices has them.
TriangleMesh weld_by_position(const std::vector<const TriangleMesh*>& parts);

}  // namespace featsense::mesh
