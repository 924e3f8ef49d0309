#include "featsense/mesh/mesh_simplification.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace featsense::mesh {
namespace {

/// Bit patterns of a position, for exact matching (a float equal to another has the same
/// bits, except 0 and -0, which marching cubes never writes as a coordinate's sign flip).
struct PositionKey {
  uint32_t x, y, z;
  friend bool operator==(const PositionKey& a, const PositionKey& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  }
};

struct PositionKeyHash {
  std::size_t operator()(const PositionKey& k) const {
    return static_cast<std::size_t>(static_cast<uint64_t>(k.x) * 73856093u ^
                                    static_cast<uint64_t>(k.y) * 19349663u ^
                                    static_cast<uint64_t>(k.z) * 83492791u);
  }
};

PositionKey key_of(const Eigen::Vector3f& p) {
  PositionKey key{};
  std::memcpy(&key.x, &p.x(), sizeof(float));
  std::memcpy(&key.y, &p.y(), sizeof(float));
  std::memcpy(&key.z, &p.z(), sizeof(float));
  return key;
}

}  // namespace

SimplifiedMesh simplify_mesh(const TriangleMesh& mesh, const SimplifySettings& settings,
                             const std::vector<bool>& held) {
  if (!(settings.target_ratio > 0.0 && settings.target_ratio <= 1.0)) {
    throw std::invalid_argument("simplify: the share of triangles to keep must be in (0, 1], got " +
                                std::to_string(settings.target_ratio));
  }
  if (!(settings.max_error_m >= 0.0)) {
    throw std::invalid_argument("simplify: the error bound must be >= 0 metres, got " +
                                std::to_string(settings.max_error_m));
  }
  if (!held.empty() && held.size() != mesh.vertices.size()) {
    throw std::invalid_argument("simplify: " + std::to_string(held.size()) + " held marks for " +
                                std::to_string(mesh.vertices.size()) + " vertices");
  }
  SimplifiedMesh out;
  if (mesh.triangles.empty()) return out;
  const std::size_t index_count = mesh.triangles.size() * 3;
  static_assert(sizeof(Eigen::Vector3i) == 3 * sizeof(unsigned int));
  const auto* indices = reinterpret_cast<const unsigned int*>(mesh.triangles.data());
  // meshoptimizer 0.18 (Debian 12) can hold only all open borders at once, which stalls on a
  // scanned surface full of small holes. It also holds every vertex that shares its position
  // with a vertex no triangle uses (it cannot tell which side of such a seam is which), so a
  // held vertex gets such a twin after the mesh's own vertices; twins are never in the output.
  std::vector<Eigen::Vector3f> positions_with_twins;
  const bool any_held = std::find(held.begin(), held.end(), true) != held.end();
  if (any_held) {
    positions_with_twins = mesh.vertices;
    for (std::size_t v = 0; v < held.size(); ++v)
      if (held[v]) positions_with_twins.push_back(mesh.vertices[v]);
  }
  const std::vector<Eigen::Vector3f>& with_twins = any_held ? positions_with_twins : mesh.vertices;
  const auto* positions = reinterpret_cast<const float*>(with_twins.data());
  const std::size_t vertex_count = with_twins.size();
  const float scale = meshopt_simplifyScale(positions, vertex_count, sizeof(Eigen::Vector3f));
  // meshoptimizer measures errors relative to the mesh's extent.
  const float relative_error =
      scale > 0.0f && std::isfinite(settings.max_error_m)
          ? static_cast<float>(settings.max_error_m / static_cast<double>(scale))
          : std::numeric_limits<float>::max();
  const auto target = static_cast<std::size_t>(std::llround(
                          static_cast<double>(mesh.triangles.size()) * settings.target_ratio)) *
                      3;
  std::vector<unsigned int> kept(index_count);
  float result_error = 0.0f;
  kept.resize(meshopt_simplify(kept.data(), indices, index_count, positions, vertex_count,
                               sizeof(Eigen::Vector3f), target, relative_error, 0u, &result_error));
  out.error_m = static_cast<double>(result_error) * static_cast<double>(scale);

  // Only the vertices still used, in their first-use order.
  std::vector<int32_t> remap(mesh.vertices.size(), -1);
  const bool normals = mesh.has_normals();
  out.mesh.triangles.reserve(kept.size() / 3);
  for (std::size_t i = 0; i < kept.size(); i += 3) {
    Eigen::Vector3i triangle;
    for (int c = 0; c < 3; ++c) {
      const unsigned int v = kept[i + static_cast<std::size_t>(c)];
      if (remap[v] < 0) {
        remap[v] = static_cast<int32_t>(out.mesh.vertices.size());
        out.mesh.vertices.push_back(mesh.vertices[v]);
        if (normals) out.mesh.normals.push_back(mesh.normals[v]);
      }
      triangle[c] = remap[v];
    }
    out.mesh.triangles.push_back(triangle);
  }
  return out;
}

TriangleMesh weld_by_position(const std::vector<const TriangleMesh*>& parts) {
  TriangleMesh out;
  // A part without vertices (a neighbour's triangles near a tile, none there) has no normals
  // to miss.
  bool normals = false;
  for (const TriangleMesh* part : parts) {
    if (part->vertices.empty()) continue;
    if (!part->has_normals()) {
      normals = false;
      break;
    }
    normals = true;
  }
  std::unordered_map<PositionKey, int32_t, PositionKeyHash> seen;
  std::vector<int32_t> remap;
  for (const TriangleMesh* part : parts) {
    remap.assign(part->vertices.size(), -1);
    for (std::size_t v = 0; v < part->vertices.size(); ++v) {
      const auto [it, inserted] =
          seen.emplace(key_of(part->vertices[v]), static_cast<int32_t>(out.vertices.size()));
      if (inserted) {
        out.vertices.push_back(part->vertices[v]);
        if (normals) out.normals.push_back(part->normals[v]);
      }
      remap[v] = it->second;
    }
    for (const Eigen::Vector3i& t : part->triangles) {
      out.triangles.emplace_back(remap[static_cast<std::size_t>(t[0])],
                                 remap[static_cast<std::size_t>(t[1])],
                                 remap[static_cast<std::size_t>(t[2])]);
    }
  }
  return out;
}

}  // namespace featsense::mesh
