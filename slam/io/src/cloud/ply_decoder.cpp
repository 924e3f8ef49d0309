// decode_ply(): the vertices of a PLY file, ascii or binary of either byte order; elements
// before the vertices (faces, ...) are walked over, those after them never touched.

#include "cloud/cloud_assembler.hpp"
#include "cloud/cloud_limits.hpp"
#include "cloud/ply_header.hpp"
#include "cloud/text_lines.hpp"

namespace featsense::slam {
namespace {

using cloud::ByteOrder;
using cloud::CloudAssembler;
using cloud::PlyElement;
using cloud::PlyHeader;
using cloud::ScalarType;

/// The vertex properties the assembler sees: scalar ones only (a list cannot be a
/// coordinate), each mapped to its assembler field.
struct VertexFields {
  std::vector<cloud::FileField> fields;
  std::vector<std::optional<size_t>> field_of_property;
};

VertexFields vertex_fields(const PlyElement& vertex) {
  VertexFields out;
  for (const cloud::PlyProperty& p : vertex.properties) {
    if (p.is_list) {
      out.field_of_property.push_back(std::nullopt);
    } else {
      out.field_of_property.push_back(out.fields.size());
      out.fields.push_back({p.name, p.type, 1});
    }
  }
  return out;
}

/// Binary records read front to back with every step checked against the end of the data.
class BinaryWalker {
 public:
  BinaryWalker(std::string_view data, ByteOrder order, const std::string& origin)
      : data_(reinterpret_cast<const uint8_t*>(data.data())),
        size_(data.size()),
        order_(order),
        origin_(origin) {}

  const uint8_t* take(size_t n, const PlyElement& element, uint64_t record) {
    if (n > size_ - pos_) {
      throw InputError(origin_ + ": data ends inside " + element.name + " " +
                       std::to_string(record) + " (byte " + std::to_string(pos_) +
                       " after the header)");
    }
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  double value(ScalarType type, const PlyElement& element, uint64_t record) {
    return cloud::load_scalar(take(cloud::size_of(type), element, record), type, order_);
  }
  /// Skips one list property; throws when its count is more than the data can hold.
  void skip_list(const cloud::PlyProperty& p, const PlyElement& element, uint64_t record) {
    const double count = value(p.count_type, element, record);
    if (!(count >= 0.0) || count > static_cast<double>(size_ - pos_)) {
      throw InputError(origin_ + ": " + element.name + " " + std::to_string(record) + ": list '" +
                       p.name + "' claims " + std::to_string(count) +
                       " items, more than the data holds");
    }
    take(static_cast<size_t>(count) * cloud::size_of(p.type), element, record);
  }
  size_t remaining() const { return size_ - pos_; }
  size_t position() const { return pos_; }
  ByteOrder order() const { return order_; }
  const uint8_t* here() const { return data_ + pos_; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  ByteOrder order_;
  const std::string& origin_;
};

void read_binary(const PlyHeader& header, size_t vertex_index, const VertexFields& fields,
                 std::string_view data, const std::string& origin, CloudAssembler& assembler) {
  BinaryWalker walker(
      data,
      header.format == PlyHeader::Format::kBinaryBigEndian ? ByteOrder::kBig : ByteOrder::kLittle,
      origin);
  for (size_t e = 0; e <= vertex_index; ++e) {
    const PlyElement& element = header.elements[e];
    const bool is_vertex = e == vertex_index;
    if (!element.has_lists()) {
      const size_t record = element.min_record_bytes();
      if (element.count > walker.remaining() / std::max<size_t>(record, 1)) {
        throw InputError(origin + ": " + std::to_string(element.count) + " " + element.name +
                         " records of " + std::to_string(record) + " bytes promised, but " +
                         std::to_string(walker.remaining()) + " bytes remain");
      }
      if (!is_vertex) {
        walker.take(static_cast<size_t>(element.count) * record, element, 0);
        continue;
      }
      // Fixed records: each used property at its offset in every record.
      const uint8_t* base = walker.here();
      std::vector<std::pair<size_t, size_t>> used;  // (field, offset)
      size_t offset = 0;
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const std::optional<size_t> f = fields.field_of_property[p];
        if (f && assembler.used(*f)) used.emplace_back(*f, offset);
        offset += cloud::size_of(element.properties[p].type);
      }
      for (const auto& [f, at] : used) {
        assembler.set_column(f, base + at, record, fields.fields[f].type, walker.order());
      }
      return;
    }
    for (uint64_t r = 0; r < element.count; ++r) {
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const cloud::PlyProperty& property = element.properties[p];
        if (property.is_list) {
          walker.skip_list(property, element, r);
          continue;
        }
        const double v = walker.value(property.type, element, r);
        const std::optional<size_t> f = is_vertex ? fields.field_of_property[p] : std::nullopt;
        if (f && assembler.used(*f)) assembler.set(static_cast<size_t>(r), *f, v);
      }
    }
  }
}

void read_ascii(const PlyHeader& header, size_t vertex_index, const VertexFields& fields,
                std::string_view data, const std::string& origin, CloudAssembler& assembler) {
  cloud::LineReader lines(data);
  for (size_t e = 0; e <= vertex_index; ++e) {
    const PlyElement& element = header.elements[e];
    const bool is_vertex = e == vertex_index;
    for (uint64_t r = 0; r < element.count; ++r) {
      std::optional<std::string_view> line;
      do {
        line = lines.next();
      } while (line && cloud::split_words(*line).empty());
      const std::string where = origin + ": " + element.name + " " + std::to_string(r);
      if (!line) {
        throw InputError(where + ": the data ends; the header promises " +
                         std::to_string(element.count) + " " + element.name + " records");
      }
      const std::vector<std::string_view> words = cloud::split_words(*line);
      size_t w = 0;
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const cloud::PlyProperty& property = element.properties[p];
        if (w >= words.size()) throw InputError(where + ": too few values on its line");
        const std::optional<double> v = cloud::parse_number(words[w]);
        if (!v) {
          throw InputError(where + ": '" + std::string(words[w].substr(0, 40)) +
                           "' is not a number");
        }
        ++w;
        if (property.is_list) {
          if (!(*v >= 0.0) || *v > static_cast<double>(words.size() - w)) {
            throw InputError(where + ": list '" + property.name + "' claims " +
                             std::string(words[w - 1].substr(0, 40)) + " items");
          }
          w += static_cast<size_t>(*v);
          continue;
        }
        const std::optional<size_t> f = is_vertex ? fields.field_of_property[p] : std::nullopt;
        if (f && assembler.used(*f)) assembler.set(static_cast<size_t>(r), *f, *v);
      }
      if (w != words.size()) throw InputError(where + ": too many values on its line");
    }
  }
}

}  // namespace

DecodedCloud decode_ply(std::string_view bytes, const std::string& origin) {
  const PlyHeader header = cloud::parse_ply_header(bytes, origin);
  size_t vertex_index = header.elements.size();
  for (size_t e = 0; e < header.elements.size(); ++e) {
    if (header.elements[e].name == "vertex") {
      vertex_index = e;
      break;
    }
  }
  if (vertex_index == header.elements.size()) {
    throw InputError(origin + ": PLY file without a 'vertex' element");
  }
  const PlyElement& vertex = header.elements[vertex_index];
  const std::string_view data = bytes.substr(header.data_offset);
  // Every vertex takes a byte at least (two in ascii): a count beyond that is a lie, caught
  // before anything is sized by it.
  if (vertex.count > cloud::kMaxPoints || vertex.count > data.size()) {
    throw InputError(origin + ": element vertex " + std::to_string(vertex.count) +
                     " promises more vertices than the " + std::to_string(data.size()) +
                     " bytes of data can hold");
  }
  const VertexFields fields = vertex_fields(vertex);
  const size_t points = static_cast<size_t>(vertex.count);
  CloudAssembler assembler(fields.fields, points, origin, /*require_float_xyz=*/false);
  if (header.format == PlyHeader::Format::kAscii) {
    read_ascii(header, vertex_index, fields, data, origin, assembler);
  } else {
    read_binary(header, vertex_index, fields, data, origin, assembler);
  }
  DecodedCloud decoded = assembler.finish("ply", static_cast<int>(points), 1);
  decoded.fields.clear();
  for (const cloud::PlyProperty& p : vertex.properties) decoded.fields.push_back(p.name);
  if (header.stamp_ns) decoded.stamp_ns = header.stamp_ns;
  return decoded;
}

}  // namespace featsense::slam
