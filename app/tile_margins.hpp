#pragma once
// The parts of a tile set's tiles that other tiles' work needs (the triangles of a tile within
// reach of a neighbour's box), cut once per tile and kept on disk until that neighbour takes
// them: each tile is read twice in all (once to cut its margins, once for its own work),
// whatever the tile set's shape, with the memory of the tiles in work. A cache of whole tiles
// does not bound this: a neighbourhood spans three columns of tiles, which grow with the map
// (the 5 km city's 140 tiles were read 400 times through a cache of 16).

#include <cstddef>
#include <filesystem>
#include <map>
#include <mutex>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::app {

class TileMargins {
 public:
  /// Keeps the parts in `dir` (created; removed with everything in it by the destructor).
  explicit TileMargins(std::filesystem::path dir);
  ~TileMargins();
  TileMargins(const TileMargins&) = delete;
  TileMargins& operator=(const TileMargins&) = delete;

  /// Keeps tile `from`'s part for tile `to` (vertices, normals, triangles; parts dropped).
  /// Safe from several threads. Throws std::runtime_error naming the file when it cannot be
  /// written (a full disk).
  void put(std::size_t to, std::size_t from, const mesh::TriangleMesh& part);
  /// The parts kept for tile `to`, by the tile they came from in ascending order; their files
  /// are removed. Safe from several threads.
  std::vector<mesh::TriangleMesh> take(std::size_t to);

 private:
  std::filesystem::path file(std::size_t to, std::size_t from) const;

  std::filesystem::path dir_;
  std::mutex mutex_;
  std::map<std::size_t, std::vector<std::size_t>> kept_;  ///< to -> the tiles it came from
};

}  // namespace featsense::app
