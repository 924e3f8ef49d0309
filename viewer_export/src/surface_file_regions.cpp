// Surfaces on disk read by region: a tile set's tiles through a small cache, a tiled point
// file, or a whole mesh file kept in memory.

#include "featsense/viewer_export/surface_file_regions.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <list>
#include <map>
#include <unordered_map>

#include "featsense/mesh/mesh_simplification.hpp"
#include "featsense/mesh/tiled_point_file.hpp"
#include "featsense/viewer_export/mesh_file_error.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::viewer_export {
namespace {

namespace fs = std::filesystem;

/// A mesh file read whole, with the grid of mesh::MeshRegions over it.
class WholeFileRegions final : public mesh::SurfaceRegions {
 public:
  explicit WholeFileRegions(const fs::path& path)
      : mesh_(read_mesh(path.string())), regions_(mesh_) {}
  Eigen::AlignedBox3d bounds() const override { return regions_.bounds(); }
  bool is_point_cloud() const override { return regions_.is_point_cloud(); }
  mesh::SurfacePiece read(const Eigen::AlignedBox3d& box) const override {
    return regions_.read(box);
  }
  std::optional<uint64_t> vertex_count() const override { return regions_.vertex_count(); }

 private:
  mesh::TriangleMesh mesh_;
  mesh::MeshRegions regions_;
};

/// GLB tiles are stored re-centred (gltf_mesh_io.hpp), so the copies of a vertex on a cut
/// come back a float rounding apart (micrometres): they are one within this distance.
constexpr double kGlbWeldM = 1e-5;

/// `mesh` with the vertices within `tolerance_m` of an earlier one merged into it (a hash grid
/// of that cell, the 27 cells around each vertex searched).
mesh::TriangleMesh weld_within(const mesh::TriangleMesh& mesh, double tolerance_m) {
  struct CellHash {
    std::size_t operator()(const Eigen::Vector3i& c) const {
      return (static_cast<std::size_t>(c.x()) * 73856093u) ^
             (static_cast<std::size_t>(c.y()) * 19349663u) ^
             (static_cast<std::size_t>(c.z()) * 83492791u);
    }
  };
  std::unordered_map<Eigen::Vector3i, std::vector<int>, CellHash> cells;
  mesh::TriangleMesh out;
  std::vector<int> remap(mesh.vertices.size(), -1);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d p = mesh.vertices[v].cast<double>();
    const Eigen::Vector3i cell = (p / tolerance_m).array().floor().cast<int>();
    for (int dz = -1; dz <= 1 && remap[v] < 0; ++dz) {
      for (int dy = -1; dy <= 1 && remap[v] < 0; ++dy) {
        for (int dx = -1; dx <= 1 && remap[v] < 0; ++dx) {
          const auto found = cells.find(cell + Eigen::Vector3i(dx, dy, dz));
          if (found == cells.end()) continue;
          for (int other : found->second) {
            if ((out.vertices[static_cast<std::size_t>(other)].cast<double>() - p).norm() <=
                tolerance_m) {
              remap[v] = other;
              break;
            }
          }
        }
      }
    }
    if (remap[v] >= 0) continue;
    remap[v] = static_cast<int>(out.vertices.size());
    cells[cell].push_back(remap[v]);
    out.vertices.push_back(mesh.vertices[v]);
    if (mesh.has_normals()) out.normals.push_back(mesh.normals[v]);
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    out.triangles.emplace_back(remap[static_cast<std::size_t>(t[0])],
                               remap[static_cast<std::size_t>(t[1])],
                               remap[static_cast<std::size_t>(t[2])]);
  }
  return out;
}

class TileSetRegions final : public mesh::SurfaceRegions {
 public:
  TileSetRegions(const fs::path& dir, std::size_t cached_tiles) : reader_(dir, cached_tiles) {
    bounds_.setEmpty();
    for (const TileSetEntry& entry : reader_.tiles()) bounds_.extend(entry.bounds);
  }

  Eigen::AlignedBox3d bounds() const override { return bounds_; }
  bool is_point_cloud() const override { return false; }

  mesh::SurfacePiece read(const Eigen::AlignedBox3d& box) const override {
    // Only the triangles that meet the box: a region's column takes a part of each of up to
    // four tiles, and welding and searching whole tiles cost four times as much.
    std::vector<mesh::TriangleMesh> clipped;
    for (std::size_t i = 0; i < reader_.tiles().size(); ++i) {
      if (!reader_.tiles()[i].bounds.intersects(box)) continue;
      clipped.push_back(mesh::triangles_meeting(*reader_.tile(i), box));
    }
    std::vector<const mesh::TriangleMesh*> parts;
    for (const mesh::TriangleMesh& part : clipped) parts.push_back(&part);
    mesh::SurfacePiece piece;
    if (parts.empty()) return piece;
    // The tiles' copies of a vertex on a cut are one vertex, as in the whole map's mesh.
    piece.mesh = reader_.weld(parts);
    return piece;
  }

 private:
  TileSetReader reader_;
  Eigen::AlignedBox3d bounds_;
};

}  // namespace

std::vector<TileSetEntry> read_tile_set_index(const fs::path& dir) {
  const fs::path index_path = dir / "tiles.json";
  std::ifstream in(index_path);
  if (!in) throw MeshFileError(index_path.string() + ": cannot be read");
  std::vector<TileSetEntry> entries;
  try {
    const nlohmann::json index = nlohmann::json::parse(in);
    for (const nlohmann::json& tile : index.at("tiles")) {
      const std::vector<double> b = tile.at("bounds_m").get<std::vector<double>>();
      if (b.size() != 6) throw MeshFileError("a tile's bounds_m is not six numbers");
      TileSetEntry entry;
      entry.x = tile.at("x").get<int32_t>();
      entry.y = tile.at("y").get<int32_t>();
      entry.bounds =
          Eigen::AlignedBox3d(Eigen::Vector3d(b[0], b[1], b[2]), Eigen::Vector3d(b[3], b[4], b[5]));
      const nlohmann::json& file = tile.contains("ply") ? tile.at("ply") : tile.at("glb");
      if (!file.is_string()) throw MeshFileError("a tile's file is not a string");
      entry.file = file.get<std::string>();
      entries.push_back(std::move(entry));
    }
  } catch (const nlohmann::json::exception& e) {
    throw MeshFileError(index_path.string() + ": not a tile set's index: " + e.what());
  } catch (const MeshFileError& e) {
    throw MeshFileError(index_path.string() + ": " + e.what());
  }
  return entries;
}

TileSetReader::TileSetReader(fs::path dir, std::size_t cached_tiles)
    : dir_(std::move(dir)),
      tiles_(read_tile_set_index(dir_)),
      cached_tiles_(std::max<std::size_t>(cached_tiles, 1)) {
  for (const TileSetEntry& entry : tiles_) glb_ = glb_ || mesh_extension(entry.file) != ".ply";
}

mesh::TriangleMesh TileSetReader::weld(const std::vector<const mesh::TriangleMesh*>& parts) const {
  if (glb_) return weld_within(mesh::weld_by_position(parts), kGlbWeldM);
  return mesh::weld_by_position(parts);
}

std::shared_ptr<const mesh::TriangleMesh> TileSetReader::tile(std::size_t i) const {
  {
    const std::lock_guard<std::mutex> lock(cache_mutex_);
    const auto found = cache_.find(i);
    if (found != cache_.end()) {
      recent_.remove(i);
      recent_.push_front(i);
      return found->second;
    }
  }
  // Read without the lock, so that other threads' tiles are read meanwhile; two threads that
  // both miss the same tile read it twice, and the cache keeps one of the equal copies.
  auto loaded =
      std::make_shared<const mesh::TriangleMesh>(read_mesh((dir_ / tiles_.at(i).file).string()));
  const std::lock_guard<std::mutex> lock(cache_mutex_);
  if (cache_.emplace(i, loaded).second) {
    recent_.push_front(i);
    while (recent_.size() > cached_tiles_) {
      cache_.erase(recent_.back());
      recent_.pop_back();
    }
  }
  return loaded;
}

bool is_tile_set(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_regular_file(dir / "tiles.json", ec);
}

std::unique_ptr<mesh::SurfaceRegions> open_tile_set_regions(const fs::path& dir,
                                                            std::size_t cached_tiles) {
  return std::make_unique<TileSetRegions>(dir, cached_tiles);
}

std::unique_ptr<mesh::SurfaceRegions> open_surface_regions(const fs::path& path) {
  if (is_tile_set(path)) return open_tile_set_regions(path);
  if (mesh::is_tiled_point_file(path)) return std::make_unique<mesh::PointFileRegions>(path);
  return std::make_unique<WholeFileRegions>(path);
}

}  // namespace featsense::viewer_export
