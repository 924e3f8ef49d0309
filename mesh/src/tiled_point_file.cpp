// Tiled point files: a per-tile voxel set thins the points as they come, buffers spill to a
// file per tile, and finish() joins the tiles into one PLY with its index in the header.

#include "featsense/mesh/tiled_point_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh {
namespace {

namespace fs = std::filesystem;

constexpr const char* kTiledComment = "featsense_tiled_points";
constexpr const char* kTileComment = "featsense_tile";
constexpr size_t kFlushPoints = 1 << 16;
/// All buffers go to disk past this many points (24 MB), however many tiles hold them.
constexpr size_t kBufferedPoints = 1 << 21;
constexpr size_t kPointBytes = 3 * sizeof(float);

int64_t floor_div(int64_t a, int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

uint64_t slot_hash(uint64_t key) {
  key ^= key >> 33;
  key *= 0xFF51AFD7ED558CCDull;
  return key ^ (key >> 33);
}

/// Voxel keys of one tile, open addressing with linear probing (0 = empty; keys are never 0).
class VoxelKeySet {
 public:
  /// True when `key` was new.
  bool insert(uint64_t key) {
    if (2 * (count_ + 1) > slots_.size()) grow();
    const size_t mask = slots_.size() - 1;
    for (size_t i = slot_hash(key) & mask;; i = (i + 1) & mask) {
      if (slots_[i] == key) return false;
      if (slots_[i] == 0) {
        slots_[i] = key;
        ++count_;
        return true;
      }
    }
  }
  size_t size() const { return count_; }

 private:
  void grow() {
    std::vector<uint64_t> old(std::max<size_t>(1 << 12, 2 * slots_.size()), 0);
    old.swap(slots_);
    count_ = 0;
    for (uint64_t k : old) {
      if (k != 0) insert(k);
    }
  }
  std::vector<uint64_t> slots_;
  size_t count_ = 0;
};

/// A voxel's key within its tile: x, y within the tile (16 bits each, x + 1 so that no key is
/// 0), z in 32 bits.
uint64_t local_key(int64_t local_x, int64_t local_y, int64_t vz) {
  return (static_cast<uint64_t>(local_x + 1) << 48) | (static_cast<uint64_t>(local_y) << 32) |
         static_cast<uint64_t>(static_cast<uint32_t>(vz));
}

void write_or_throw(std::ofstream& out, const void* data, size_t bytes, const fs::path& path) {
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  if (!out) throw MeshError(path.string() + ": writing failed (disk full?)");
}

std::vector<float> read_floats(const fs::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw MeshError(path.string() + ": cannot be read");
  const auto bytes = static_cast<size_t>(in.tellg());
  std::vector<float> values(bytes / sizeof(float));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(bytes));
  if (!in) throw MeshError(path.string() + ": cannot be read");
  return values;
}

}  // namespace

struct TiledPointWriter::Tile {
  std::unique_ptr<VoxelKeySet> voxels;  ///< null once forgotten
  bool forgotten = false;               ///< its part may hold repeats
  uint64_t last_use = 0;
  std::vector<float> buffer;  ///< x, y, z not yet on disk
  uint64_t spilled = 0;       ///< points in its part file
  float z_min = std::numeric_limits<float>::infinity();
  float z_max = -std::numeric_limits<float>::infinity();
};

TiledPointWriter::TiledPointWriter(fs::path path, TiledPointSettings settings)
    : path_(std::move(path)), parts_dir_(path_.string() + ".parts"), settings_(settings) {
  if (!(settings_.voxel_size_m > 0.0) || !(settings_.tile_size_m >= settings_.voxel_size_m)) {
    throw MeshError("tiled points: voxel " + std::to_string(settings_.voxel_size_m) +
                    " m and tile " + std::to_string(settings_.tile_size_m) +
                    " m must be positive, the tile at least a voxel");
  }
  tile_voxels_ = std::llround(settings_.tile_size_m / settings_.voxel_size_m);
  if (tile_voxels_ > 65535) {
    throw MeshError("tiled points: a tile of " + std::to_string(settings_.tile_size_m) +
                    " m is more than 65535 voxels wide");
  }
  std::error_code ec;
  fs::remove_all(parts_dir_, ec);
  fs::create_directories(parts_dir_, ec);
  if (ec) throw MeshError(parts_dir_.string() + ": cannot create the folder: " + ec.message());
}

TiledPointWriter::~TiledPointWriter() {
  if (finished_) return;  // its parts are gone, and the folder may be another writer's now
  std::error_code ec;
  fs::remove_all(parts_dir_, ec);
}

fs::path TiledPointWriter::part_path(const std::pair<int64_t, int64_t>& key) const {
  return parts_dir_ / (std::to_string(key.first) + "_" + std::to_string(key.second) + ".bin");
}

TiledPointWriter::Tile& TiledPointWriter::tile_of(int64_t x, int64_t y) {
  std::unique_ptr<Tile>& tile = tiles_[{x, y}];
  if (!tile) tile = std::make_unique<Tile>();
  return *tile;
}

void TiledPointWriter::add(const Eigen::Vector3f& p) {
  if (!p.allFinite()) return;
  const double v = settings_.voxel_size_m;
  const auto vx = static_cast<int64_t>(std::floor(p.x() / v));
  const auto vy = static_cast<int64_t>(std::floor(p.y() / v));
  const auto vz = static_cast<int64_t>(std::floor(p.z() / v));
  const int64_t tx = floor_div(vx, tile_voxels_);
  const int64_t ty = floor_div(vy, tile_voxels_);
  Tile& tile = tile_of(tx, ty);
  tile.last_use = ++clock_;
  if (!tile.voxels) tile.voxels = std::make_unique<VoxelKeySet>();
  const size_t before = tile.voxels->size();
  if (!tile.voxels->insert(local_key(vx - tx * tile_voxels_, vy - ty * tile_voxels_, vz))) return;
  remembered_ += tile.voxels->size() - before;
  tile.buffer.insert(tile.buffer.end(), {p.x(), p.y(), p.z()});
  tile.z_min = std::min(tile.z_min, p.z());
  tile.z_max = std::max(tile.z_max, p.z());
  ++points_;
  ++buffered_;
  if (tile.buffer.size() >= 3 * kFlushPoints) flush({tx, ty}, tile);
  if (buffered_ > kBufferedPoints) {
    for (auto& [key, other] : tiles_) flush(key, *other);
  }
  if (remembered_ > settings_.remembered_voxels) forget_oldest_voxels();
}

void TiledPointWriter::flush(const std::pair<int64_t, int64_t>& key, Tile& tile) {
  if (tile.buffer.empty()) return;
  const fs::path part = part_path(key);
  std::ofstream out(part, std::ios::binary | std::ios::app);
  if (!out) throw MeshError(part.string() + ": cannot open for writing");
  write_or_throw(out, tile.buffer.data(), tile.buffer.size() * sizeof(float), part);
  tile.spilled += tile.buffer.size() / 3;
  buffered_ -= tile.buffer.size() / 3;
  tile.buffer.clear();
  tile.buffer.shrink_to_fit();
}

void TiledPointWriter::forget_oldest_voxels() {
  // Down to three quarters of the budget, so that forgetting is not done at every point.
  while (remembered_ > settings_.remembered_voxels * 3 / 4) {
    Tile* oldest = nullptr;
    for (auto& [key, tile] : tiles_) {
      if (tile->voxels && tile->last_use != clock_ &&
          (!oldest || tile->last_use < oldest->last_use)) {
        oldest = tile.get();
      }
    }
    if (!oldest) return;  // only the tile in use remembers: it keeps its voxels
    remembered_ -= oldest->voxels->size();
    oldest->voxels.reset();
    oldest->forgotten = true;
  }
}

size_t TiledPointWriter::finish() {
  // Every tile to disk; a tile that was forgotten is thinned again from its part, keeping
  // the first point of each voxel as the set would have.
  const double v = settings_.voxel_size_m;
  points_ = 0;
  for (auto& [key, tile] : tiles_) {
    flush(key, *tile);
    tile->voxels.reset();
    if (tile->forgotten) {
      const fs::path part = part_path(key);
      const std::vector<float> all = read_floats(part);
      std::vector<float> kept;
      VoxelKeySet voxels;
      for (size_t i = 0; i + 2 < all.size(); i += 3) {
        const auto vx = static_cast<int64_t>(std::floor(all[i] / v));
        const auto vy = static_cast<int64_t>(std::floor(all[i + 1] / v));
        const auto vz = static_cast<int64_t>(std::floor(all[i + 2] / v));
        if (voxels.insert(
                local_key(vx - key.first * tile_voxels_, vy - key.second * tile_voxels_, vz))) {
          kept.insert(kept.end(), {all[i], all[i + 1], all[i + 2]});
        }
      }
      std::ofstream out(part, std::ios::binary | std::ios::trunc);
      if (!out) throw MeshError(part.string() + ": cannot open for writing");
      write_or_throw(out, kept.data(), kept.size() * sizeof(float), part);
      tile->spilled = kept.size() / 3;
    }
    points_ += tile->spilled;
  }

  std::ofstream out(path_, std::ios::binary | std::ios::trunc);
  if (!out) throw MeshError(path_.string() + ": cannot open for writing");
  std::ostringstream header;
  header.imbue(std::locale::classic());
  header.precision(9);
  header << "ply\nformat binary_little_endian 1.0\n"
         << "comment " << kTiledComment << " 1 voxel_m " << v << " tile_voxels " << tile_voxels_
         << "\n";
  uint64_t first = 0;
  for (const auto& [key, tile] : tiles_) {
    if (tile->spilled == 0) continue;
    header << "comment " << kTileComment << " " << key.first << " " << key.second << " " << first
           << " " << tile->spilled << " " << tile->z_min << " " << tile->z_max << "\n";
    first += tile->spilled;
  }
  header << "element vertex " << points_
         << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  const std::string text = header.str();
  write_or_throw(out, text.data(), text.size(), path_);
  std::vector<char> block(1 << 20);
  for (const auto& [key, tile] : tiles_) {
    if (tile->spilled == 0) continue;
    const fs::path part = part_path(key);
    std::ifstream in(part, std::ios::binary);
    if (!in) throw MeshError(part.string() + ": cannot be read");
    while (in) {
      in.read(block.data(), static_cast<std::streamsize>(block.size()));
      write_or_throw(out, block.data(), static_cast<size_t>(in.gcount()), path_);
    }
  }
  out.close();
  if (!out) throw MeshError(path_.string() + ": writing failed (disk full?)");
  tiles_.clear();
  std::error_code ec;
  fs::remove_all(parts_dir_, ec);
  finished_ = true;
  return points_;
}

namespace {

struct PlyHeader {
  uint64_t bytes = 0;
  uint64_t vertices = 0;
  std::vector<std::string> comments;
};

/// The header of a binary little-endian PLY of float x, y, z and nothing else.
PlyHeader read_point_header(std::ifstream& in, const fs::path& path) {
  const std::string name = path.string();
  PlyHeader header;
  std::string line;
  if (!std::getline(in, line) || line != "ply") throw MeshError(name + ": not a PLY file");
  std::vector<std::string> properties;
  int elements = 0;
  bool binary = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    words.imbue(std::locale::classic());
    std::string word;
    words >> word;
    if (word == "end_header") {
      header.bytes = static_cast<uint64_t>(in.tellg());
      if (!binary || elements != 1 ||
          properties != std::vector<std::string>{"float x", "float y", "float z"}) {
        throw MeshError(name + ": not a binary little-endian PLY of float x, y, z points");
      }
      return header;
    }
    if (word == "format") {
      std::string format;
      words >> format;
      binary = format == "binary_little_endian";
    } else if (word == "comment") {
      header.comments.push_back(line.substr(std::min<size_t>(line.size(), 8)));
    } else if (word == "element") {
      std::string element;
      words >> element >> header.vertices;
      ++elements;
      if (element != "vertex" || !words) throw MeshError(name + ": unexpected element " + line);
    } else if (word == "property") {
      std::string type, property;
      words >> type >> property;
      properties.push_back(type + " " + property);
    }
  }
  throw MeshError(name + ": the PLY header has no end_header");
}

}  // namespace

TiledPointFile::TiledPointFile(fs::path path) : path_(std::move(path)) {
  const std::string name = path_.string();
  std::ifstream in(path_, std::ios::binary);
  if (!in) throw MeshError(name + ": cannot be read");
  const PlyHeader header = read_point_header(in, path_);
  header_bytes_ = header.bytes;
  points_ = header.vertices;
  std::error_code ec;
  const uint64_t size = fs::file_size(path_, ec);
  if (ec || size < header_bytes_ + points_ * kPointBytes) {
    throw MeshError(name + ": truncated (" + std::to_string(points_) + " points announced)");
  }
  double voxel_m = 0.0;
  int64_t tile_voxels = 0;
  for (const std::string& comment : header.comments) {
    std::istringstream words(comment);
    words.imbue(std::locale::classic());
    std::string tag;
    words >> tag;
    if (tag == kTiledComment) {
      std::string version, voxel_word, tile_word;
      words >> version >> voxel_word >> voxel_m >> tile_word >> tile_voxels;
      if (!words || !(voxel_m > 0.0) || tile_voxels <= 0) {
        throw MeshError(name + ": a malformed tile index: " + comment);
      }
      tiled_ = true;
    } else if (tag == kTileComment) {
      Tile tile;
      float z_min = 0.0f, z_max = 0.0f;  // as written: floats in 9 digits, read back exactly
      words >> tile.x >> tile.y >> tile.first >> tile.count >> z_min >> z_max;
      if (!words || !tiled_) throw MeshError(name + ": a malformed tile: " + comment);
      // A point's voxel is floor(p / voxel) in floating point: one a rounding away from a
      // tile's edge may lie just outside it, hence the millimetre of slack.
      const double edge = static_cast<double>(tile_voxels) * voxel_m;
      const double slack = 1e-3;
      tile.bounds = Eigen::AlignedBox3d(
          Eigen::Vector3d(static_cast<double>(tile.x) * edge - slack,
                          static_cast<double>(tile.y) * edge - slack, z_min),
          Eigen::Vector3d(static_cast<double>(tile.x + 1) * edge + slack,
                          static_cast<double>(tile.y + 1) * edge + slack, z_max));
      tiles_.push_back(tile);
    }
  }
  uint64_t expected_first = 0;
  for (const Tile& tile : tiles_) {
    if (tile.first != expected_first) throw MeshError(name + ": the tile index does not add up");
    expected_first += tile.count;
  }
  if (tiled_ && expected_first != points_) {
    throw MeshError(name + ": the tiles hold " + std::to_string(expected_first) + " points, the " +
                    "header " + std::to_string(points_));
  }
  if (!tiled_) {
    // One tile of everything, its bounds from its points.
    Tile all;
    all.count = points_;
    all.bounds.setEmpty();
    constexpr uint64_t kBlock = 1 << 20;
    for (uint64_t first = 0; first < points_; first += kBlock) {
      const Tile block{0, 0, first, std::min(kBlock, points_ - first), {}};
      for (const Eigen::Vector3f& p : read_tile(block)) all.bounds.extend(p.cast<double>());
    }
    tiles_ = {all};
  }
}

Eigen::AlignedBox3d TiledPointFile::bounds() const {
  Eigen::AlignedBox3d box;
  box.setEmpty();
  for (const Tile& tile : tiles_) {
    if (tile.count > 0) box.extend(tile.bounds);
  }
  return box;
}

std::vector<Eigen::Vector3f> TiledPointFile::read_tile(const Tile& tile) const {
  std::vector<Eigen::Vector3f> points(tile.count);
  if (tile.count == 0) return points;
  std::ifstream in(path_, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(header_bytes_ + tile.first * kPointBytes));
  in.read(reinterpret_cast<char*>(points.data()),
          static_cast<std::streamsize>(tile.count * kPointBytes));
  if (!in) throw MeshError(path_.string() + ": cannot be read");
  return points;
}

std::vector<Eigen::Vector3f> TiledPointFile::read(const Eigen::AlignedBox3d& box) const {
  std::vector<Eigen::Vector3f> inside;
  for (const Tile& tile : tiles_) {
    if (!box.isEmpty() && !tile.bounds.intersects(box)) continue;
    for (const Eigen::Vector3f& p : read_tile(tile)) {
      if (box.isEmpty() || box.contains(p.cast<double>())) inside.push_back(p);
    }
  }
  return inside;
}

bool is_tiled_point_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  try {
    const PlyHeader header = read_point_header(in, path);
    return std::any_of(header.comments.begin(), header.comments.end(),
                       [](const std::string& c) { return c.rfind(kTiledComment, 0) == 0; });
  } catch (const MeshError&) {
    return false;
  }
}

}  // namespace featsense::mesh
