// Tile margins on disk: a raw little-endian record per part (the counts, then the arrays as
// they lie in memory), read back by the same process, so no format beyond this file.

#include "tile_margins.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace featsense::app {

namespace fs = std::filesystem;

namespace {

struct PartHeader {
  uint64_t vertices = 0;
  uint64_t triangles = 0;
  uint64_t normals = 0;
};

template <typename T>
void write_array(std::ofstream& out, const std::vector<T>& values) {
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(T)));
}

template <typename T>
void read_array(std::ifstream& in, std::vector<T>& values, uint64_t count) {
  values.resize(count);
  in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(count * sizeof(T)));
}

}  // namespace

TileMargins::TileMargins(fs::path dir) : dir_(std::move(dir)) {
  fs::remove_all(dir_);
  fs::create_directories(dir_);
}

TileMargins::~TileMargins() {
  std::error_code ignored;
  fs::remove_all(dir_, ignored);
}

fs::path TileMargins::file(std::size_t to, std::size_t from) const {
  return dir_ / (std::to_string(to) + "_from_" + std::to_string(from) + ".part");
}

void TileMargins::put(std::size_t to, std::size_t from, const mesh::TriangleMesh& part) {
  const fs::path path = file(to, from);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    const PartHeader header{part.vertices.size(), part.triangles.size(), part.normals.size()};
    out.write(reinterpret_cast<const char*>(&header), sizeof(header));
    write_array(out, part.vertices);
    write_array(out, part.normals);
    write_array(out, part.triangles);
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + path.string() + " (disk full?)");
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  kept_[to].push_back(from);
}

std::vector<mesh::TriangleMesh> TileMargins::take(std::size_t to) {
  std::vector<std::size_t> sources;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto found = kept_.find(to);
    if (found == kept_.end()) return {};
    sources = std::move(found->second);
    kept_.erase(found);
  }
  std::sort(sources.begin(), sources.end());
  std::vector<mesh::TriangleMesh> parts(sources.size());
  for (std::size_t k = 0; k < sources.size(); ++k) {
    const fs::path path = file(to, sources[k]);
    {
      std::ifstream in(path, std::ios::binary);
      PartHeader header;
      in.read(reinterpret_cast<char*>(&header), sizeof(header));
      read_array(in, parts[k].vertices, header.vertices);
      read_array(in, parts[k].normals, header.normals);
      read_array(in, parts[k].triangles, header.triangles);
      if (!in) throw std::runtime_error("cannot read " + path.string());
    }
    fs::remove(path);
  }
  return parts;
}

}  // namespace featsense::app
