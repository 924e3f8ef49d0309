#pragma once
/// Surfaces on disk read by region (mesh/surface_regions.hpp), for comparisons that must not
/// hold a city: a tile set's folder (tile_set.hpp) a few tiles at a time, a tiled point file
/// (the simulator's gt_points.ply) a tile at a time, any other mesh or cloud file whole.

#include <cstdint>
#include <filesystem>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "featsense/mesh/surface_regions.hpp"

namespace featsense::viewer_export {

/// One full-resolution tile of a tile set, as its index (tiles.json) lists it.
struct TileSetEntry {
  int32_t x = 0;
  int32_t y = 0;
  Eigen::AlignedBox3d bounds;  ///< map frame, metres
  std::string file;            ///< PLY where written, else GLB; relative to the folder
};

/// The tiles of the tile set in `dir`. Throws MeshFileError naming tiles.json when it cannot be
/// read or is not a tile set's index.
std::vector<TileSetEntry> read_tile_set_index(const std::filesystem::path& dir);

/// A tile set's full-resolution tiles read from disk as they are asked for, the last
/// `cached_tiles` kept in memory; safe to ask from several threads at once. Throws
/// MeshFileError naming the file that cannot be read.
class TileSetReader {
 public:
  explicit TileSetReader(std::filesystem::path dir, std::size_t cached_tiles = 16);
  const std::vector<TileSetEntry>& tiles() const { return tiles_; }
  /// Tile `i` of tiles(), from the cache or from its file.
  std::shared_ptr<const mesh::TriangleMesh> tile(std::size_t i) const;
  /// Parts of this set's tiles as one mesh, the parts' triangles in order, with the copies of
  /// a vertex on a cut between tiles once, as in the whole map's mesh: the same position in
  /// PLY tiles, within 10 micrometres where tiles are GLB only (stored re-centred, so the
  /// copies come back a float rounding apart).
  mesh::TriangleMesh weld(const std::vector<const mesh::TriangleMesh*>& parts) const;

 private:
  std::filesystem::path dir_;
  std::vector<TileSetEntry> tiles_;
  bool glb_ = false;  ///< some tiles are GLB only
  std::size_t cached_tiles_;
  // The cache is not the tile set's state: reading stays const.
  mutable std::map<std::size_t, std::shared_ptr<const mesh::TriangleMesh>> cache_;
  mutable std::list<std::size_t> recent_;  ///< most recent first
  mutable std::mutex cache_mutex_;
};

/// A tile set's full-resolution tiles (tiles.json; PLY where written, else GLB), the last
/// `cached_tiles` kept in memory; the copies of a vertex on a cut between tiles come once
/// (GLB tiles are re-centred: copies within 10 micrometres are one).
/// Throws MeshFileError naming the folder when its index cannot be read.
std::unique_ptr<mesh::SurfaceRegions> open_tile_set_regions(const std::filesystem::path& dir,
                                                            std::size_t cached_tiles = 16);

/// A tile set's folder, a tiled point file or a mesh file (read_mesh), by what `path` is.
/// Throws MeshFileError (PlyError, mesh::MeshError) naming the path.
std::unique_ptr<mesh::SurfaceRegions> open_surface_regions(const std::filesystem::path& path);

/// True when `dir` holds a tile set's index (tiles.json).
bool is_tile_set(const std::filesystem::path& dir);

}  // namespace featsense::viewer_export
