#pragma once
/// The map cut into square tiles of whole chunk columns, meshed one tile at a time, so that
/// meshing a map of any extent holds one tile's mesh (and the chunks in flight) in memory.
///
/// Tile (x, y) owns the cubes whose lower corner voxel lies in chunks x * n .. x * n + n - 1
/// along x (and the same along y), every z, where n is `chunks_per_tile`. The tiles of a map
/// therefore hold exactly the cubes of `extract_mesh` over the whole map (a partition: no cube
/// twice, none left out), and a vertex on the border of two tiles is computed from the same
/// voxels by the same arithmetic in both: the two tiles' copies are equal bit for bit, so tiles
/// weld by position without seams.

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/storage/chunk_store.hpp"

namespace featsense::mesh {

struct TileIndex {
  int32_t x = 0;
  int32_t y = 0;

  friend bool operator==(const TileIndex& a, const TileIndex& b) {
    return a.x == b.x && a.y == b.y;
  }
  friend bool operator<(const TileIndex& a, const TileIndex& b) {
    return a.x != b.x ? a.x < b.x : a.y < b.y;
  }
};

/// Chunks per tile edge for a wished tile size: the nearest whole number of chunks, at least
/// one. Throws std::invalid_argument when the size is not a positive number.
int32_t chunks_per_tile_for(double tile_size_m, const storage::MapMetadata& metadata);

class MapTiles {
 public:
  /// Groups the store's chunks into tiles of `chunks_per_tile` chunk columns per side. The
  /// store must outlive this object and not change while it is used. Throws
  /// std::invalid_argument when chunks_per_tile < 1.
  MapTiles(storage::ChunkStore& store, int32_t chunks_per_tile);

  /// The tiles that hold stored chunks, sorted.
  std::vector<TileIndex> tiles() const;
  int32_t chunks_per_tile() const { return chunks_per_tile_; }
  /// Edge of a tile, metres.
  double tile_size_m() const;
  /// The region of the tile's cubes in the map frame: x and y from the centre of its first
  /// voxel to the centre of the first voxel of the next tile; z over all its stored chunks'
  /// cubes. Every vertex of its mesh lies inside (up to the rounding of its float coordinates).
  Eigen::AlignedBox3d bounds(TileIndex tile) const;
  /// Where the cut before tile column (or row) `tile` lies along x (or y), metres: the centre of
  /// the tile's first voxel. A vertex on a cut has exactly this coordinate, as a float, in both
  /// tiles that share it.
  double cut_m(int32_t tile) const;
  /// Stored chunks of the tile.
  std::size_t chunk_count(TileIndex tile) const;

  /// The tile's part of the whole map's mesh (see the file comment); the settings' bbox and
  /// min_weight apply as in extract_mesh. Empty when the tile has no surface.
  TriangleMesh mesh(TileIndex tile, const MeshingSettings& settings,
                    MeshingStats* stats = nullptr) const;

  /// The tile holding a chunk.
  TileIndex tile_of(const storage::ChunkKey& key) const;

 private:
  /// The stored keys whose column lies in chunk columns [x0, x1] x [y0, y1], sorted.
  std::vector<storage::ChunkKey> keys_in(int32_t x0, int32_t x1, int32_t y0, int32_t y1) const;

  storage::ChunkStore& store_;
  int32_t chunks_per_tile_;
  std::vector<storage::ChunkKey> keys_;  ///< every stored key, sorted (x, then y, then z)
};

}  // namespace featsense::mesh
