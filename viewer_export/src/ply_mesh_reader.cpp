// PLY reader for meshes and point clouds: parses the header, then reads every element in
// order, keeping the vertex positions, normals and faces.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {
namespace {

enum class Encoding { kAscii, kBinaryLittle, kBinaryBig };

struct Property {
  std::string name;
  std::string type;        ///< value type (list: item type)
  std::string count_type;  ///< list count type, empty for a scalar property
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

size_t type_size(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

template <typename T>
T load(const char* bytes, bool swap) {
  char copy[sizeof(T)];
  std::memcpy(copy, bytes, sizeof(T));
  if (swap) {
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(copy[i], copy[sizeof(T) - 1 - i]);
  }
  T value;
  std::memcpy(&value, copy, sizeof(T));
  return value;
}

class Reader {
 public:
  Reader(std::istream& in, const std::string& path, Encoding encoding)
      : in_(in), path_(path), encoding_(encoding) {}

  double read(const std::string& type) {
    if (encoding_ == Encoding::kAscii) {
      double value = 0.0;
      if (!(in_ >> value)) fail("expected a number");
      return value;
    }
    char bytes[8];
    const size_t size = type_size(type);
    if (!in_.read(bytes, static_cast<std::streamsize>(size))) fail("file ends early");
    const bool swap = encoding_ == Encoding::kBinaryBig;
    if (type == "char" || type == "int8") return load<int8_t>(bytes, swap);
    if (type == "uchar" || type == "uint8") return load<uint8_t>(bytes, swap);
    if (type == "short" || type == "int16") return load<int16_t>(bytes, swap);
    if (type == "ushort" || type == "uint16") return load<uint16_t>(bytes, swap);
    if (type == "int" || type == "int32") return load<int32_t>(bytes, swap);
    if (type == "uint" || type == "uint32") return load<uint32_t>(bytes, swap);
    if (type == "float" || type == "float32") return load<float>(bytes, swap);
    return load<double>(bytes, swap);
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw PlyError(path_ + ": " + what + " (in element data)");
  }

 private:
  std::istream& in_;
  const std::string& path_;
  Encoding encoding_;
};

int find(const Element& element, const std::string& name) {
  for (size_t i = 0; i < element.properties.size(); ++i) {
    if (element.properties[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

/// The header: its encoding and the elements with their properties, up to end_header.
struct PlyHeader {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
};

PlyHeader read_header(std::istream& in, const std::string& path) {
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) {
    throw PlyError(path + ": not a PLY file (no 'ply' magic)");
  }
  auto header_error = [&](size_t number, const std::string& what) {
    return PlyError(path + ": header line " + std::to_string(number) + ": " + what);
  };
  PlyHeader header;
  Encoding& encoding = header.encoding;
  std::vector<Element>& elements = header.elements;
  bool has_format = false;
  for (size_t number = 2;; ++number) {
    if (!std::getline(in, line)) throw header_error(number, "no end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") break;
    if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
    if (keyword == "format") {
      std::string name;
      words >> name;
      if (name == "ascii")
        encoding = Encoding::kAscii;
      else if (name == "binary_little_endian")
        encoding = Encoding::kBinaryLittle;
      else if (name == "binary_big_endian")
        encoding = Encoding::kBinaryBig;
      else
        throw header_error(number, "unknown format '" + name + "'");
      has_format = true;
    } else if (keyword == "element") {
      Element element;
      long long count = -1;
      if (!(words >> element.name >> count) || count < 0) {
        throw header_error(number, "expected 'element NAME COUNT'");
      }
      element.count = static_cast<size_t>(count);
      elements.push_back(element);
    } else if (keyword == "property") {
      if (elements.empty()) throw header_error(number, "property before any element");
      Property property;
      std::string type;
      words >> type;
      if (type == "list") {
        words >> property.count_type >> property.type;
        if (type_size(property.count_type) == 0 || property.count_type == "float" ||
            property.count_type == "double") {
          throw header_error(number, "bad list count type '" + property.count_type + "'");
        }
      } else {
        property.type = type;
      }
      if (!(words >> property.name) || type_size(property.type) == 0) {
        throw header_error(number, "expected 'property TYPE NAME' with a PLY type");
      }
      elements.back().properties.push_back(property);
    } else {
      throw header_error(number, "unknown keyword '" + keyword + "'");
    }
  }
  if (!has_format) throw PlyError(path + ": header has no format line");
  return header;
}

}  // namespace

mesh::TriangleMesh read_ply_mesh(const std::string& path, MeshAttributes* attributes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PlyError(path + ": cannot open");
  const PlyHeader header = read_header(in, path);
  const std::vector<Element>& elements = header.elements;

  mesh::TriangleMesh mesh;
  Reader reader(in, path, header.encoding);
  bool has_vertices = false;
  for (const Element& element : elements) {
    const bool is_vertex = element.name == "vertex";
    const bool is_face = element.name == "face";
    int xyz[3] = {-1, -1, -1};
    int nxyz[3] = {-1, -1, -1};
    int indices = -1;
    int rgb[3] = {-1, -1, -1};
    std::vector<std::pair<size_t, size_t>> scalar_of_property;  // (property, layer)
    MeshAttributes read_attributes;
    if (is_vertex) {
      const char* color_names[3] = {"red", "green", "blue"};
      for (int k = 0; k < 3; ++k) rgb[k] = find(element, color_names[k]);
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const std::string& name = element.properties[p].name;
        if (name.rfind("scalar_", 0) == 0 && element.properties[p].count_type.empty()) {
          scalar_of_property.emplace_back(p, read_attributes.scalars.size());
          read_attributes.scalars.push_back({name.substr(7), {}});
        }
      }
      has_vertices = true;
      const char* names[3] = {"x", "y", "z"};
      const char* normal_names[3] = {"nx", "ny", "nz"};
      for (int k = 0; k < 3; ++k) {
        xyz[k] = find(element, names[k]);
        nxyz[k] = find(element, normal_names[k]);
        if (xyz[k] < 0) throw PlyError(path + ": vertex element has no '" + names[k] + "'");
      }
      // A header may claim more than the file holds: reserve no more than a plausible share.
      mesh.vertices.reserve(std::min<size_t>(element.count, size_t{1} << 20));
    }
    if (is_face) {
      indices = find(element, "vertex_indices");
      if (indices < 0) indices = find(element, "vertex_index");
      if (indices < 0 || element.properties[static_cast<size_t>(indices)].count_type.empty()) {
        throw PlyError(path + ": face element has no 'vertex_indices' list");
      }
    }
    const bool normals = nxyz[0] >= 0 && nxyz[1] >= 0 && nxyz[2] >= 0;
    const bool colors = rgb[0] >= 0 && rgb[1] >= 0 && rgb[2] >= 0;
    std::vector<double> values(element.properties.size());
    std::vector<long long> polygon;
    for (size_t item = 0; item < element.count; ++item) {
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (property.count_type.empty()) {
          values[p] = reader.read(property.type);
          continue;
        }
        const double count = reader.read(property.count_type);
        if (count < 0 || count > 1e6) reader.fail("bad list length in element " + element.name);
        polygon.clear();
        for (auto k = static_cast<long long>(count); k > 0; --k) {
          const double index = reader.read(property.type);
          if (!(index >= 0 && index < 2147483647.0)) {
            reader.fail("vertex index out of range in element " + element.name);
          }
          polygon.push_back(static_cast<long long>(index));
        }
        if (static_cast<int>(p) == indices) {
          for (size_t k = 2; k < polygon.size(); ++k) {
            mesh.triangles.emplace_back(static_cast<int>(polygon[0]),
                                        static_cast<int>(polygon[k - 1]),
                                        static_cast<int>(polygon[k]));
          }
        }
      }
      if (is_vertex) {
        mesh.vertices.emplace_back(values[static_cast<size_t>(xyz[0])],
                                   values[static_cast<size_t>(xyz[1])],
                                   values[static_cast<size_t>(xyz[2])]);
        if (normals) {
          mesh.normals.emplace_back(values[static_cast<size_t>(nxyz[0])],
                                    values[static_cast<size_t>(nxyz[1])],
                                    values[static_cast<size_t>(nxyz[2])]);
        }
        if (colors) {
          Eigen::Matrix<uint8_t, 3, 1> color;
          for (int k = 0; k < 3; ++k) {
            color[k] = static_cast<uint8_t>(
                std::lround(std::clamp(values[static_cast<size_t>(rgb[k])], 0.0, 255.0)));
          }
          read_attributes.colors.push_back(color);
        }
        for (const auto& [p, layer] : scalar_of_property) {
          read_attributes.scalars[layer].values.push_back(static_cast<float>(values[p]));
        }
      }
    }
    if (is_vertex && attributes != nullptr) *attributes = std::move(read_attributes);
  }
  if (!has_vertices) throw PlyError(path + ": no vertex element");
  try {
    mesh::validate(mesh, path);
  } catch (const mesh::MeshError& e) {
    throw PlyError(e.what());
  }
  return mesh;
}

}  // namespace featsense::viewer_export
