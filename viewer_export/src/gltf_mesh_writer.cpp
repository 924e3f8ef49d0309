// glTF 2.0 writer: one buffer (positions, normals, colours, layers, indices), one mesh under an
// origin node that carries the re-centring offset.

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "featsense/mesh/navigation_layers.hpp"
#include "featsense/viewer_export/gltf_mesh_io.hpp"

namespace featsense::viewer_export {
namespace {

constexpr int kFloat = 5126;
constexpr int kUnsignedByte = 5121;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;

/// Map frame (Z up) to glTF (Y up), both right-handed: a +90 deg turn about X.
Eigen::Vector3d to_gltf(const Eigen::Vector3d& p) { return {p.x(), p.z(), -p.y()}; }

/// The binary buffer and the JSON that describes its pieces.
class BufferBuilder {
 public:
  explicit BufferBuilder(nlohmann::json* gltf) : gltf_(gltf) {}

  /// Appends raw bytes as a new buffer view (4-byte aligned); returns its index.
  int add_view(const void* data, size_t bytes, int target) {
    while (data_.size() % 4 != 0) data_.push_back('\0');
    nlohmann::json view = {{"buffer", 0}, {"byteOffset", data_.size()}, {"byteLength", bytes}};
    view["target"] = target;
    data_.append(static_cast<const char*>(data), bytes);
    (*gltf_)["bufferViews"].push_back(view);
    return static_cast<int>((*gltf_)["bufferViews"].size()) - 1;
  }

  /// Adds an accessor over a new view; returns its index.
  int add_accessor(const void* data, size_t bytes, int target, int component_type, size_t count,
                   const std::string& type, bool normalized = false) {
    nlohmann::json accessor = {{"bufferView", add_view(data, bytes, target)},
                               {"componentType", component_type},
                               {"count", count},
                               {"type", type}};
    if (normalized) accessor["normalized"] = true;
    (*gltf_)["accessors"].push_back(accessor);
    return static_cast<int>((*gltf_)["accessors"].size()) - 1;
  }

  nlohmann::json& accessor(int index) { return (*gltf_)["accessors"][static_cast<size_t>(index)]; }
  const std::string& data() const { return data_; }

 private:
  nlohmann::json* gltf_;
  std::string data_;
};

/// Bounding-box centre rounded to whole metres: exact in float32 up to 16,000 km.
Eigen::Vector3d origin_of(const mesh::TriangleMesh& mesh) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d high = -low;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    low = low.cwiseMin(v.cast<double>());
    high = high.cwiseMax(v.cast<double>());
  }
  return (0.5 * (low + high)).array().round();
}

/// Unit normals per vertex; the mesh's own where usable, else area-weighted face normals.
std::vector<Eigen::Vector3f> unit_normals(const mesh::TriangleMesh& mesh) {
  mesh::TriangleMesh without = mesh;
  without.normals.clear();
  std::vector<Eigen::Vector3f> computed(mesh.vertices.size(), Eigen::Vector3f::UnitZ());
  if (!mesh.triangles.empty()) computed = mesh::vertex_normals(without);
  if (!mesh.has_normals()) return computed;
  std::vector<Eigen::Vector3f> normals = mesh.normals;
  for (size_t i = 0; i < normals.size(); ++i) {
    const float length = normals[i].norm();
    // The validator rejects non-unit normals; a zero or broken one takes the face normal.
    normals[i] = std::isfinite(length) && length > 1e-6f ? Eigen::Vector3f(normals[i] / length)
                                                         : computed[i];
  }
  return normals;
}

std::string attribute_name(const std::string& layer) {
  std::string name = "_";
  for (const char c : layer) {
    name += std::isalnum(static_cast<unsigned char>(c))
                ? static_cast<char>(std::toupper(static_cast<unsigned char>(c)))
                : '_';
  }
  return name;
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw MeshFileError(path + ": cannot open for writing");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw MeshFileError(path + ": write failed");
}

void put_u32(std::string* out, uint32_t value) {
  char bytes[4];
  std::memcpy(bytes, &value, 4);  // little-endian on every platform we build for
  out->append(bytes, 4);
}

}  // namespace

void write_gltf_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                     const MeshAttributes& attributes, bool binary) {
  const size_t n = mesh.vertices.size();
  if (n == 0) throw MeshFileError(path + ": the mesh is empty");
  const Eigen::Vector3d origin = origin_of(mesh);

  nlohmann::json gltf;
  gltf["asset"] = {{"version", "2.0"}, {"generator", "featsense"}};
  gltf["bufferViews"] = nlohmann::json::array();
  gltf["accessors"] = nlohmann::json::array();
  BufferBuilder buffer(&gltf);

  std::vector<float> positions;
  positions.reserve(3 * n);
  Eigen::Vector3f low = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f high = -low;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    const Eigen::Vector3f local = to_gltf(v.cast<double>() - origin).cast<float>();
    low = low.cwiseMin(local);
    high = high.cwiseMax(local);
    positions.insert(positions.end(), local.data(), local.data() + 3);
  }
  nlohmann::json primitive_attributes;
  const int position = buffer.add_accessor(positions.data(), positions.size() * sizeof(float),
                                           kArrayBuffer, kFloat, n, "VEC3");
  buffer.accessor(position)["min"] = {low.x(), low.y(), low.z()};
  buffer.accessor(position)["max"] = {high.x(), high.y(), high.z()};
  primitive_attributes["POSITION"] = position;

  std::vector<float> normals;
  normals.reserve(3 * n);
  for (const Eigen::Vector3f& normal : unit_normals(mesh)) {
    const Eigen::Vector3f g = to_gltf(normal.cast<double>()).cast<float>();
    normals.insert(normals.end(), g.data(), g.data() + 3);
  }
  primitive_attributes["NORMAL"] = buffer.add_accessor(
      normals.data(), normals.size() * sizeof(float), kArrayBuffer, kFloat, n, "VEC3");

  if (!attributes.colors.empty()) {
    if (attributes.colors.size() != n) throw MeshFileError(path + ": colours do not match");
    // RGBA rather than RGB: vertex attributes must be 4-byte aligned.
    std::vector<uint8_t> rgba;
    rgba.reserve(4 * n);
    for (const auto& c : attributes.colors) rgba.insert(rgba.end(), {c[0], c[1], c[2], 255});
    primitive_attributes["COLOR_0"] =
        buffer.add_accessor(rgba.data(), rgba.size(), kArrayBuffer, kUnsignedByte, n, "VEC4", true);
  }
  for (const VertexScalar& scalar : attributes.scalars) {
    if (scalar.values.size() != n) {
      throw MeshFileError(path + ": layer '" + scalar.name + "' does not match the vertices");
    }
    primitive_attributes[attribute_name(scalar.name)] = buffer.add_accessor(
        scalar.values.data(), n * sizeof(float), kArrayBuffer, kFloat, n, "SCALAR");
  }

  nlohmann::json primitive = {{"attributes", primitive_attributes}, {"material", 0}};
  if (mesh.triangles.empty()) {
    primitive["mode"] = 0;  // points
  } else {
    std::vector<uint32_t> indices;
    indices.reserve(3 * mesh.triangles.size());
    for (const Eigen::Vector3i& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) indices.push_back(static_cast<uint32_t>(t[k]));
    }
    const int accessor =
        buffer.add_accessor(indices.data(), indices.size() * sizeof(uint32_t), kElementArrayBuffer,
                            kUnsignedInt, indices.size(), "SCALAR");
    primitive["indices"] = accessor;
    primitive["mode"] = 4;  // triangles
  }
  gltf["meshes"] = {{{"name", "featsense_mesh"}, {"primitives", {primitive}}}};
  // White, rough, not metallic: the vertex colours are what shows.
  gltf["materials"] = {{{"name", "vertex_colors"},
                        {"doubleSided", true},
                        {"pbrMetallicRoughness",
                         {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}},
                          {"metallicFactor", 0.0},
                          {"roughnessFactor", 1.0}}}}};
  const Eigen::Vector3d origin_gltf = to_gltf(origin);
  gltf["nodes"] = {
      {{"name", "map_origin"},
       {"translation", {origin_gltf.x(), origin_gltf.y(), origin_gltf.z()}},
       {"children", {1}},
       {"extras",
        {{"featsense_origin_map_m", {origin.x(), origin.y(), origin.z()}},
         {"featsense_frame",
          "map frame, metres, Z up; glTF (x, y, z) = map (x, z, -y); positions are relative "
          "to this node's translation"}}}},
      {{"name", "featsense_mesh"}, {"mesh", 0}}};
  gltf["scenes"] = {{{"nodes", {0}}}};
  gltf["scene"] = 0;

  const std::string& data = buffer.data();
  nlohmann::json buffer_json = {{"byteLength", data.size()}};
  if (binary) {
    gltf["buffers"] = {buffer_json};
    std::string json = gltf.dump();
    while (json.size() % 4 != 0) json += ' ';
    std::string bin = data;
    while (bin.size() % 4 != 0) bin += '\0';
    std::string glb;
    put_u32(&glb, 0x46546C67u);  // "glTF"
    put_u32(&glb, 2);
    put_u32(&glb, static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
    put_u32(&glb, static_cast<uint32_t>(json.size()));
    put_u32(&glb, 0x4E4F534Au);  // "JSON"
    glb += json;
    put_u32(&glb, static_cast<uint32_t>(bin.size()));
    put_u32(&glb, 0x004E4942u);  // "BIN"
    glb += bin;
    write_bytes(path, glb);
  } else {
    const std::filesystem::path bin_path = std::filesystem::path(path).replace_extension(".bin");
    buffer_json["uri"] = bin_path.filename().string();
    gltf["buffers"] = {buffer_json};
    write_bytes(path, gltf.dump(1) + "\n");
    write_bytes(bin_path.string(), data);
  }
}

}  // namespace featsense::viewer_export
