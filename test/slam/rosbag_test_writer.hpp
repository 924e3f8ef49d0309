#pragma once
// A small ROS1 bag writer (format 2.0) for tests: chunks of each compression, the index at
// the end or none (as a recording cut off before closing), and serializers for the
// messages the reader decodes. Written from the ROS bag 2.0 format description, so that
// tests compare what the reader returns with what was written.

#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace featsense::test {

/// Appends little-endian values the way ROS serializes them.
class RosBytes {
 public:
  template <typename T>
  RosBytes& value(T v) {
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &v, sizeof(T));
    return *this;
  }
  RosBytes& u8(uint8_t v) { return value(v); }
  RosBytes& u32(uint32_t v) { return value(v); }
  RosBytes& u64(uint64_t v) { return value(v); }
  RosBytes& time(int64_t ns) {
    return u32(static_cast<uint32_t>(ns / 1000000000)).u32(static_cast<uint32_t>(ns % 1000000000));
  }
  RosBytes& raw(const std::vector<uint8_t>& bytes) {
    bytes_.insert(bytes_.end(), bytes.begin(), bytes.end());
    return *this;
  }
  RosBytes& raw(const std::string& bytes) {
    bytes_.insert(bytes_.end(), bytes.begin(), bytes.end());
    return *this;
  }
  RosBytes& string(const std::string& s) { return u32(static_cast<uint32_t>(s.size())).raw(s); }
  RosBytes& byte_array(const std::vector<uint8_t>& bytes) {
    return u32(static_cast<uint32_t>(bytes.size())).raw(bytes);
  }
  /// A record header field: u32 length, then name=value.
  RosBytes& field(const std::string& name, const std::vector<uint8_t>& value) {
    u32(static_cast<uint32_t>(name.size() + 1 + value.size())).raw(name + "=");
    return raw(value);
  }
  RosBytes& field(const std::string& name, const std::string& value) {
    return field(name, std::vector<uint8_t>(value.begin(), value.end()));
  }

  const std::vector<uint8_t>& bytes() const { return bytes_; }
  size_t size() const { return bytes_.size(); }

 private:
  std::vector<uint8_t> bytes_;
};

template <typename T>
std::vector<uint8_t> le_bytes(T v) {
  return RosBytes().value(v).bytes();
}

inline std::vector<uint8_t> time_bytes(int64_t ns) { return RosBytes().time(ns).bytes(); }

/// A record: u32 header length, header, u32 data length, data.
inline std::vector<uint8_t> bag_record(const RosBytes& header, const std::vector<uint8_t>& data) {
  return RosBytes()
      .u32(static_cast<uint32_t>(header.size()))
      .raw(header.bytes())
      .u32(static_cast<uint32_t>(data.size()))
      .raw(data)
      .bytes();
}

enum class TestCompression { kNone, kBz2, kLz4 };

inline const char* compression_name(TestCompression c) {
  return c == TestCompression::kNone ? "none" : c == TestCompression::kBz2 ? "bz2" : "lz4";
}

inline std::vector<uint8_t> compress(TestCompression c, const std::vector<uint8_t>& in) {
  if (c == TestCompression::kNone) return in;
  std::vector<uint8_t> out;
  if (c == TestCompression::kBz2) {
    unsigned int size = static_cast<unsigned int>(in.size() + in.size() / 100 + 600);
    out.resize(size);
    // libbz2 takes non-const input and rejects a null pointer (an empty vector's data()).
    std::vector<uint8_t> source = in;
    source.push_back(0);
    const int rc = BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &size,
                                            reinterpret_cast<char*>(source.data()),
                                            static_cast<unsigned int>(in.size()), 9, 0, 0);
    if (rc != BZ_OK) throw std::runtime_error("bz2 compression failed");
    out.resize(size);
  } else {
    // With a content checksum, so that the damage tests can tell corrupt data.
    LZ4F_preferences_t preferences{};
    preferences.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
    out.resize(LZ4F_compressFrameBound(in.size(), &preferences));
    const size_t size =
        LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), &preferences);
    if (LZ4F_isError(size)) throw std::runtime_error("lz4 compression failed");
    out.resize(size);
  }
  return out;
}

/// Writes a bag as rosbag does: the version line, a bag header record padded to 4096 bytes,
/// chunks (a connection's record in the chunk of its first message) each followed by its
/// index data records, and at the end the connection and chunk info records, with the
/// header's index_pos pointing at them.
class TestBagWriter {
 public:
  explicit TestBagWriter(TestCompression compression, size_t chunk_bytes = 768 * 1024)
      : compression_(compression), chunk_bytes_(chunk_bytes) {
    file_.raw(std::string("#ROSBAG V2.0\n")).raw(bag_header(0, 0, 0));
    unindexed_ = file_;
  }

  uint32_t add_connection(const std::string& topic, const std::string& type,
                          const std::string& definition = "") {
    const auto id = static_cast<uint32_t>(connections_.size());
    connections_.push_back({topic, type, definition, false});
    return id;
  }

  void add_message(uint32_t connection, int64_t time_ns, const std::vector<uint8_t>& data) {
    Connection& c = connections_.at(connection);
    if (!c.written) {
      chunk_.raw(connection_record(connection));
      c.written = true;
    }
    chunk_index_[connection].push_back({time_ns, static_cast<uint32_t>(chunk_.size())});
    RosBytes header;
    header.field("op", std::vector<uint8_t>{0x02})
        .field("conn", le_bytes(connection))
        .field("time", time_bytes(time_ns));
    chunk_.raw(bag_record(header, data));
    chunk_start_ = chunk_messages_ == 0 ? time_ns : std::min(chunk_start_, time_ns);
    chunk_end_ = chunk_messages_ == 0 ? time_ns : std::max(chunk_end_, time_ns);
    ++chunk_messages_;
    if (chunk_.size() >= chunk_bytes_) flush_chunk();
  }

  /// The whole bag. Without the index: as a recording cut off before closing (no index
  /// records, nothing after the last chunk, index_pos 0).
  std::vector<uint8_t> finish(bool with_index = true) {
    flush_chunk();
    std::vector<uint8_t> bag = file_.bytes();
    if (with_index) {
      const uint64_t index_pos = bag.size();
      RosBytes tail;
      for (uint32_t id = 0; id < connections_.size(); ++id) tail.raw(connection_record(id));
      for (const ChunkInfo& info : chunk_infos_) {
        RosBytes header;
        header.field("op", std::vector<uint8_t>{0x06})
            .field("ver", le_bytes(uint32_t{1}))
            .field("chunk_pos", le_bytes(info.position))
            .field("start_time", time_bytes(info.start_ns))
            .field("end_time", time_bytes(info.end_ns))
            .field("count", le_bytes(static_cast<uint32_t>(info.counts.size())));
        RosBytes data;
        for (const auto& [conn, count] : info.counts) data.u32(conn).u32(count);
        tail.raw(bag_record(header, data.bytes()));
      }
      bag.insert(bag.end(), tail.bytes().begin(), tail.bytes().end());
      const std::vector<uint8_t> header =
          bag_header(index_pos, static_cast<uint32_t>(connections_.size()),
                     static_cast<uint32_t>(chunk_infos_.size()));
      std::copy(header.begin(), header.end(), bag.begin() + 13);
    } else {
      // A cut-off recording has no index records after its chunks either.
      bag = unindexed_.bytes();
    }
    return bag;
  }

  /// File offsets of the chunk records written so far.
  std::vector<uint64_t> chunk_offsets() const {
    std::vector<uint64_t> offsets;
    for (const ChunkInfo& info : chunk_infos_) offsets.push_back(info.position);
    return offsets;
  }

 private:
  struct Connection {
    std::string topic;
    std::string type;
    std::string definition;
    bool written;
  };
  struct IndexEntry {
    int64_t time_ns;
    uint32_t offset;
  };
  struct ChunkInfo {
    uint64_t position;
    int64_t start_ns;
    int64_t end_ns;
    std::map<uint32_t, uint32_t> counts;
  };

  static std::vector<uint8_t> bag_header(uint64_t index_pos, uint32_t conn_count,
                                         uint32_t chunk_count) {
    RosBytes header;
    header.field("op", std::vector<uint8_t>{0x03})
        .field("index_pos", le_bytes(index_pos))
        .field("conn_count", le_bytes(conn_count))
        .field("chunk_count", le_bytes(chunk_count));
    const size_t padding = 4096 - 8 - header.size();
    return bag_record(header, std::vector<uint8_t>(padding, ' '));
  }

  std::vector<uint8_t> connection_record(uint32_t id) const {
    const Connection& c = connections_.at(id);
    RosBytes header;
    header.field("op", std::vector<uint8_t>{0x07})
        .field("conn", le_bytes(id))
        .field("topic", c.topic);
    RosBytes data;
    data.field("topic", c.topic)
        .field("type", c.type)
        .field("md5sum", std::string(32, '0'))
        .field("message_definition", c.definition);
    return bag_record(header, data.bytes());
  }

  void flush_chunk() {
    if (chunk_.size() == 0) return;
    ChunkInfo info;
    info.position = file_.size();
    info.start_ns = chunk_start_;
    info.end_ns = chunk_end_;
    RosBytes header;
    header.field("op", std::vector<uint8_t>{0x05})
        .field("compression", std::string(compression_name(compression_)))
        .field("size", le_bytes(static_cast<uint32_t>(chunk_.size())));
    const std::vector<uint8_t> chunk_record =
        bag_record(header, compress(compression_, chunk_.bytes()));
    file_.raw(chunk_record);
    unindexed_.raw(chunk_record);
    for (const auto& [conn, entries] : chunk_index_) {
      RosBytes index_header;
      index_header.field("op", std::vector<uint8_t>{0x04})
          .field("ver", le_bytes(uint32_t{1}))
          .field("conn", le_bytes(conn))
          .field("count", le_bytes(static_cast<uint32_t>(entries.size())));
      RosBytes data;
      for (const IndexEntry& e : entries) data.time(e.time_ns).u32(e.offset);
      file_.raw(bag_record(index_header, data.bytes()));
      info.counts[conn] = static_cast<uint32_t>(entries.size());
    }
    chunk_infos_.push_back(info);
    chunk_ = RosBytes();
    chunk_index_.clear();
    chunk_messages_ = 0;
  }

  TestCompression compression_;
  size_t chunk_bytes_;
  std::vector<Connection> connections_;
  RosBytes file_;
  RosBytes unindexed_;  ///< the same bag without any index records
  RosBytes chunk_;
  std::map<uint32_t, std::vector<IndexEntry>> chunk_index_;
  int64_t chunk_start_ = 0;
  int64_t chunk_end_ = 0;
  size_t chunk_messages_ = 0;
  std::vector<ChunkInfo> chunk_infos_;
};

// ---------------------------------------------------------------------------------------
// Messages

/// PointField datatypes (sensor_msgs/PointField).
enum TestDatatype : uint8_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kFloat32 = 7,
  kFloat64 = 8,
};

inline uint32_t datatype_size(uint8_t datatype) {
  static const uint32_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return datatype <= 8 ? sizes[datatype] : 0;
}

struct TestField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = kFloat32;
  uint32_t count = 1;
};

/// A sensor_msgs/PointCloud2 to serialize, every member settable (also to wrong values).
struct TestCloud {
  uint32_t seq = 0;
  int64_t stamp_ns = 0;
  std::string frame_id = "lidar";
  uint32_t height = 0;
  uint32_t width = 0;
  std::vector<TestField> fields;
  uint8_t is_bigendian = 0;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  std::vector<uint8_t> data;
  uint8_t is_dense = 0;

  /// Adds a field after the last one (no padding) and grows point_step.
  void add_field(const std::string& name, uint8_t datatype) {
    fields.push_back({name, point_step, datatype, 1});
    point_step += datatype_size(datatype);
  }
  /// Sizes data for height x width points (row_step = width x point_step).
  void allocate(uint32_t rows, uint32_t cols) {
    height = rows;
    width = cols;
    row_step = width * point_step;
    data.assign(static_cast<size_t>(row_step) * height, 0);
  }
  /// Writes a value into a point's field, converted to the field's datatype.
  void set(size_t point, const std::string& name, double value) {
    for (const TestField& f : fields) {
      if (f.name != name) continue;
      uint8_t* p = data.data() + point * point_step + f.offset;
      switch (f.datatype) {
        case kInt8:
          return store(p, static_cast<int8_t>(value));
        case kUint8:
          return store(p, static_cast<uint8_t>(value));
        case kInt16:
          return store(p, static_cast<int16_t>(value));
        case kUint16:
          return store(p, static_cast<uint16_t>(value));
        case kInt32:
          return store(p, static_cast<int32_t>(value));
        case kUint32:
          return store(p, static_cast<uint32_t>(value));
        case kFloat32:
          return store(p, static_cast<float>(value));
        case kFloat64:
          return store(p, value);
        default:
          throw std::logic_error("bad datatype");
      }
    }
    throw std::logic_error("no field " + name);
  }

  std::vector<uint8_t> serialize() const {
    RosBytes out;
    out.u32(seq).time(stamp_ns).string(frame_id).u32(height).u32(width);
    out.u32(static_cast<uint32_t>(fields.size()));
    for (const TestField& f : fields) out.string(f.name).u32(f.offset).u8(f.datatype).u32(f.count);
    out.u8(is_bigendian).u32(point_step).u32(row_step).byte_array(data).u8(is_dense);
    return out.bytes();
  }

 private:
  template <typename T>
  static void store(uint8_t* p, T v) {
    std::memcpy(p, &v, sizeof(T));
  }
};

inline std::vector<uint8_t> serialize_string_message(const std::string& text) {
  return RosBytes().string(text).bytes();
}

}  // namespace featsense::test
