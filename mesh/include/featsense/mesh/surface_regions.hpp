#pragma once
/// A surface (a mesh, or a point cloud) read a region at a time, so that comparing a city's
/// map with its truth never holds either whole: compare_by_region (region_comparison.hpp)
/// reads what it needs around one region, then the next.
///
/// Sources: a mesh in memory (MeshRegions, bucketed on a grid), a tiled point file on disk
/// (PointFileRegions, tiled_point_file.hpp), another source moved by a rigid transform
/// (MovedRegions); the tile set on disk is viewer_export's (tile_set_regions.hpp).

#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "featsense/mesh/tiled_point_file.hpp"
#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh {

/// What a source gives for a box: its triangles (or points) there, each vertex once.
struct SurfacePiece {
  TriangleMesh mesh;
  /// Per vertex of `mesh`, its index in the whole source where the source has one order
  /// (SurfaceRegions::vertex_count()); empty otherwise.
  std::vector<uint64_t> source_index;
};

class SurfaceRegions {
 public:
  virtual ~SurfaceRegions() = default;
  /// Of everything; empty when there is nothing.
  virtual Eigen::AlignedBox3d bounds() const = 0;
  virtual bool is_point_cloud() const = 0;
  /// Every triangle whose bounding box meets `box` (for a cloud: every point inside it), more
  /// allowed. Each vertex of the source comes once (a tile set's copies of a vertex on a cut
  /// are one), so that the regions of a comparison count it once.
  virtual SurfacePiece read(const Eigen::AlignedBox3d& box) const = 0;
  /// The number of vertices of the whole, where pieces give their source_index.
  virtual std::optional<uint64_t> vertex_count() const { return std::nullopt; }
};

/// A mesh (or cloud) in memory, its triangles (points) bucketed on an x, y grid of `cell_m`.
/// Keeps a reference: `mesh` must outlive it. Throws MeshError for an invalid mesh (validate:
/// a non-finite coordinate, an index out of range).
class MeshRegions final : public SurfaceRegions {
 public:
  explicit MeshRegions(const TriangleMesh& mesh, double cell_m = 25.0);
  Eigen::AlignedBox3d bounds() const override { return bounds_; }
  bool is_point_cloud() const override { return mesh_.is_point_cloud(); }
  SurfacePiece read(const Eigen::AlignedBox3d& box) const override;
  std::optional<uint64_t> vertex_count() const override { return mesh_.vertices.size(); }

 private:
  const TriangleMesh& mesh_;
  double cell_m_;
  Eigen::AlignedBox3d bounds_;
  Eigen::Vector2i cells_ = Eigen::Vector2i::Zero();  ///< grid size, from bounds_.min()
  /// Items (triangles, then loose vertices) per cell, CSR: cell c's are
  /// items_[first_[c] .. first_[c + 1]).
  std::vector<uint64_t> first_;
  std::vector<uint32_t> items_;
  /// Items past the triangles are vertices: of a cloud, all; of a mesh, those in no triangle.
  std::vector<uint32_t> loose_;
  size_t vertex_of(size_t item) const;
};

/// A tiled point file (gt_points.ply) read tile by tile.
class PointFileRegions final : public SurfaceRegions {
 public:
  explicit PointFileRegions(const std::filesystem::path& path) : file_(path) {}
  Eigen::AlignedBox3d bounds() const override { return file_.bounds(); }
  bool is_point_cloud() const override { return true; }
  SurfacePiece read(const Eigen::AlignedBox3d& box) const override;

 private:
  TiledPointFile file_;
};

/// Another source seen through T (its points p appear at T p): the truth moved into a map's
/// frame. Keeps a reference to `source`.
class MovedRegions final : public SurfaceRegions {
 public:
  MovedRegions(const SurfaceRegions& source, const Eigen::Isometry3d& T);
  Eigen::AlignedBox3d bounds() const override;
  bool is_point_cloud() const override { return source_.is_point_cloud(); }
  SurfacePiece read(const Eigen::AlignedBox3d& box) const override;
  std::optional<uint64_t> vertex_count() const override { return source_.vertex_count(); }

 private:
  const SurfaceRegions& source_;
  Eigen::Isometry3d T_;
};

/// The bounding box of `box` moved by T.
Eigen::AlignedBox3d moved_box(const Eigen::AlignedBox3d& box, const Eigen::Isometry3d& T);

}  // namespace featsense::mesh
