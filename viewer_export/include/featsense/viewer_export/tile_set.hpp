#pragma once
/// A map's mesh as a set of tiles: one mesh per tile at full resolution (GLB, and PLY where
/// asked), an index of them (`tiles.json`), and an OGC 3D Tiles 1.1 tileset (`tileset.json`)
/// whose quadtree of coarser levels lets a viewer (CesiumJS, three.js 3d-tiles-renderer) stream
/// a map of any size: the whole map coarse, full detail where one looks.
///
/// The tiles are those of mesh::MapTiles (whole chunk columns, welded without seams). A parent
/// of the quadtree holds its (up to) four children simplified to a quarter (within an error
/// bound that grows with the level) and joined, their outer border held so that neighbours of
/// one level meet. A parent's geometric error is the larger of the summed simplification errors
/// on the way down from it (meshoptimizer's estimate, metres) and its resolution, 2^level
/// voxels (its vertices lie about that far apart); a leaf's is 0. Memory: one tile's full mesh and,
/// per level of the quadtree, up to four coarser meshes of about a tile's size: bounded by the
/// tile, not by the map.
///
/// Layout of `dir`: `tileset.json`, `tiles.json`, `tiles/<level>/<x>_<y>.glb` (level 0: the
/// full-resolution tiles, also `.ply`). Frames: the map frame, Z up, metres; the GLB content is
/// Y up as glTF wants and 3D Tiles turns it back (gltf_mesh_io.hpp). No geographic placement:
/// the tileset's origin is the map's.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/mesh/mesh_cleanup.hpp"
#include "featsense/storage/chunk_store.hpp"

namespace featsense::viewer_export {

struct TileSetSettings {
  double tile_size_m = 50.0;      ///< rounded to whole chunks (mesh::chunks_per_tile_for)
  mesh::MeshingSettings meshing;  ///< min weight, bbox, threads of the marching cubes
  bool write_ply = true;          ///< each full-resolution tile also as PLY
  /// Where given, each full-resolution tile is cleaned before it is written (mesh_cleanup.hpp),
  /// its cuts held: what reaches a cut is kept and a cut is not a hole, so tiles still meet.
  std::optional<mesh::CleanupSettings> cleanup;
  double level_ratio = 0.25;  ///< share of a child's triangles its parent keeps
  /// A child simplified for its parent moves the surface by at most this share of the
  /// parent's edge: fewer triangles than level_ratio are kept where the surface allows, more
  /// where it does not (thin structure, many open borders), never a collapse that distorts it.
  double max_error_share = 0.001;
  /// A viewer loads the root first: levels are added above the quadtree's root, each a quarter
  /// of the one below, until the root holds at most this many triangles.
  std::size_t root_triangles = 200'000;
  /// Where > 0: the report's `overview` is the whole map at the finest level whose tiles hold
  /// at most this many triangles together (for a plan view of a map too large to mesh whole).
  std::size_t overview_triangles = 0;
  /// Tiles finished at once (cleaned, simplified, written) beside the meshing of the next
  /// ones. Each holds its mesh and its cleanup's work, up to about 1 GB for a dense city tile,
  /// so this, not the cores, sets how many such tiles are in memory: with one per core, the GPU
  /// machine's 16 cores peaked at 3.6 GB on the city's first km with cleanup, 2.4 GB with 2
  /// (2 cores: 0.9 GB; what else grows with the threads is not bounded here). The marching
  /// cubes still use `meshing.threads`.
  std::size_t tiles_in_work = 2;
  /// Called after each full-resolution tile: tiles done, tiles in all.
  std::function<void(std::size_t, std::size_t)> progress;
};

/// One tile of the tileset's quadtree, for the report and tileset.json.
struct TileSetNode {
  int level = 0;  ///< 0: full resolution
  /// Level 0: the tile's index (mesh::TileIndex); above: the node's place in the quadtree,
  /// counted from the first tile and halved per level.
  int32_t x = 0;
  int32_t y = 0;
  Eigen::AlignedBox3d box;         ///< of its content and its children's, map frame
  double geometric_error_m = 0.0;  ///< 0 at level 0
  std::string content;             ///< GLB, relative to the tile set's folder
  std::size_t triangles = 0;       ///< of its content
  std::vector<TileSetNode> children;
};

struct TileSetLevel {
  int level = 0;
  std::size_t tiles = 0;
  std::size_t triangles = 0;
  double max_geometric_error_m = 0.0;
};

struct TileSetReport {
  double tile_size_m = 0.0;          ///< after rounding to whole chunks
  std::size_t tiles = 0;             ///< full-resolution tiles with a surface
  std::size_t triangles = 0;         ///< of the full-resolution tiles
  std::size_t vertices = 0;          ///< of the full-resolution tiles (border ones twice)
  std::size_t chunks = 0;            ///< meshed
  std::vector<TileSetLevel> levels;  ///< finest first
  /// With cleanup: the tiles' reports summed (counts and seconds; is_* not meaningful).
  std::optional<mesh::CleanupReport> cleanup;
  /// The marching cubes (on the calling thread, parallel within); the simplification and the
  /// files run beside them, on other threads, and their seconds are summed over those threads.
  double meshing_seconds = 0.0;
  double simplifying_seconds = 0.0;
  double writing_seconds = 0.0;
  double seconds = 0.0;  ///< the whole, wall clock
  TileSetNode root;
  /// With overview_triangles: the finest level within the budget, its tiles welded; -1 and
  /// empty when even the root holds more.
  int overview_level = -1;
  mesh::TriangleMesh overview;
};

/// Meshes `store` tile by tile into `dir` (created; files already there are overwritten).
/// Throws std::invalid_argument for bad settings, std::runtime_error when the map has no
/// surface or a file cannot be written.
TileSetReport write_tile_set(storage::ChunkStore& store, const std::string& dir,
                             const TileSetSettings& settings);

/// tileset.json of a quadtree (3D Tiles 1.1, refine REPLACE, box bounding volumes). The
/// tileset's own geometric error (the error of drawing nothing) is the root box's half
/// diagonal.
std::string tileset_json(const TileSetNode& root);

}  // namespace featsense::viewer_export
