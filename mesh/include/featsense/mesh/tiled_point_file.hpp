#pragma once
/// A point cloud too large for memory, written and read a square tile at a time: the
/// simulator's dense truth (gt_points.ply), which a town's loop makes 80 M points of.
///
/// The file is an ordinary binary little-endian PLY of float x, y, z (any tool opens it),
/// its points grouped by tile, with the index in the header's comments:
///   comment featsense_tiled_points 1 voxel_m V tile_voxels N
///   comment featsense_tile X Y FIRST COUNT ZMIN ZMAX     (one per tile, FIRST ascending)
/// Tile (X, Y) holds the points whose voxel (floor(p / V)) has floor(vx / N) = X and
/// floor(vy / N) = Y: whole voxels, so each voxel lies in exactly one tile. Its x, y extent is
/// [X, X + 1) * N * V (and the same in y). The writer keeps one point per voxel (the first it
/// was given), so the file is the same set of points as one thinned in one piece, in
/// another order.
///
/// Target featsense::mesh_types (the standard library and Eigen only): the simulator writes
/// it, the comparison reads it.

#include <Eigen/Geometry>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace featsense::mesh {

struct TiledPointSettings {
  double voxel_size_m = 0.02;
  /// The tile's edge, metres, rounded to whole voxels (at most 65535 of them).
  double tile_size_m = 32.0;
  /// Voxels remembered for thinning, over the tiles most recently added to (16 bytes each
  /// at most). A tile forgotten and added to again is thinned once more at the end, from disk.
  size_t remembered_voxels = 16'000'000;
};

/// Writes a tiled point file with memory bounded by `remembered_voxels` and a buffer per
/// tile; the points wait on disk in `path`.parts/ until finish(). Throws MeshError naming
/// the path when a file cannot be written.
class TiledPointWriter {
 public:
  TiledPointWriter(std::filesystem::path path, TiledPointSettings settings = {});
  ~TiledPointWriter();  ///< without finish(), removes what it wrote
  TiledPointWriter(const TiledPointWriter&) = delete;
  TiledPointWriter& operator=(const TiledPointWriter&) = delete;

  /// Keeps `p` when no point of its voxel was kept before (non-finite points are dropped).
  void add(const Eigen::Vector3f& p);
  /// Writes the file and removes the parts; returns the number of points.
  size_t finish();
  /// Points kept so far (a forgotten tile may still hold repeats, until finish()).
  size_t points() const { return points_; }

 private:
  struct Tile;
  Tile& tile_of(int64_t x, int64_t y);
  void forget_oldest_voxels();
  void flush(const std::pair<int64_t, int64_t>& key, Tile& tile);
  std::filesystem::path part_path(const std::pair<int64_t, int64_t>& key) const;

  std::filesystem::path path_;
  std::filesystem::path parts_dir_;
  TiledPointSettings settings_;
  int64_t tile_voxels_ = 0;
  std::map<std::pair<int64_t, int64_t>, std::unique_ptr<Tile>> tiles_;
  size_t remembered_ = 0;
  uint64_t clock_ = 0;
  size_t points_ = 0;
  size_t buffered_ = 0;  ///< points in the tiles' buffers
  bool finished_ = false;
};

/// Reads a tiled point file by region. A PLY of float x, y, z without the index is read as one
/// tile holding everything (its bounds from its points).
class TiledPointFile {
 public:
  struct Tile {
    int64_t x = 0, y = 0;
    uint64_t first = 0, count = 0;
    Eigen::AlignedBox3d bounds;  ///< x, y: the tile's square; z: its points' extent
  };

  /// Throws MeshError naming the path when the file is not such a PLY, or is truncated.
  explicit TiledPointFile(std::filesystem::path path);

  /// True when the file carries tile comments: is_tiled_point_file.
  bool tiled() const { return tiled_; }
  uint64_t points() const { return points_; }
  const std::vector<Tile>& tiles() const { return tiles_; }
  Eigen::AlignedBox3d bounds() const;
  /// The points of the tiles that meet `box`, those inside it; all points when empty box.
  std::vector<Eigen::Vector3f> read(const Eigen::AlignedBox3d& box) const;
  std::vector<Eigen::Vector3f> read_tile(const Tile& tile) const;

 private:
  std::filesystem::path path_;
  uint64_t header_bytes_ = 0;
  uint64_t points_ = 0;
  bool tiled_ = false;
  std::vector<Tile> tiles_;
};

/// True when `path` is a PLY whose header holds the tiled-points comment (reads the header
/// only; false for anything else, unreadable files included).
bool is_tiled_point_file(const std::filesystem::path& path);

}  // namespace featsense::mesh
