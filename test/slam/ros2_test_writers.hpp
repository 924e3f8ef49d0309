#pragma once
// Writes ROS 2 data for the reader tests, from the specifications (CDR of OMG XCDR1, rosbag2's
// sqlite3 schema, mcap.dev/spec), independently of the readers under test: CDR messages,
// sqlite3 bag files with their metadata.yaml, and MCAP files (chunks uncompressed, zstd or
// lz4 through the real libraries, with or without a summary).

#include <lz4frame.h>
#include <sqlite3.h>
#include <zlib.h>
#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "slam/rosbag_test_writer.hpp"

namespace featsense::test {

/// Appends CDR (little-endian, encapsulation 00 01 00 00), aligning each primitive to its
/// size counted from the end of the encapsulation header.
class CdrBytes {
 public:
  CdrBytes() : out_{0x00, 0x01, 0x00, 0x00} {}

  CdrBytes& u8(uint8_t v) { return raw(&v, 1); }
  CdrBytes& u16(uint16_t v) { return aligned(&v, 2); }
  CdrBytes& u32(uint32_t v) { return aligned(&v, 4); }
  CdrBytes& i32(int32_t v) { return aligned(&v, 4); }
  CdrBytes& time(int64_t ns) {
    return i32(static_cast<int32_t>(ns / 1000000000)).u32(static_cast<uint32_t>(ns % 1000000000));
  }
  CdrBytes& string(const std::string& s) {
    u32(static_cast<uint32_t>(s.size() + 1));
    raw(s.data(), s.size());
    return u8(0);
  }
  CdrBytes& f64(double v) { return aligned(&v, 8); }
  CdrBytes& bytes(const std::vector<uint8_t>& b) { return raw(b.data(), b.size()); }
  CdrBytes& byte_sequence(const std::vector<uint8_t>& b) {
    u32(static_cast<uint32_t>(b.size()));
    return bytes(b);
  }
  const std::vector<uint8_t>& data() const { return out_; }

 private:
  CdrBytes& aligned(const void* p, size_t size) {
    while ((out_.size() - 4) % size != 0) out_.push_back(0);
    return raw(p, size);
  }
  CdrBytes& raw(const void* p, size_t size) {
    const auto* b = static_cast<const uint8_t*>(p);
    out_.insert(out_.end(), b, b + size);
    return *this;
  }
  std::vector<uint8_t> out_;
};

/// A sensor_msgs/msg/PointCloud2 in CDR (ROS 2 has no seq in the header).
inline std::vector<uint8_t> cdr_pointcloud2(const TestCloud& cloud) {
  CdrBytes out;
  out.time(cloud.stamp_ns).string(cloud.frame_id).u32(cloud.height).u32(cloud.width);
  out.u32(static_cast<uint32_t>(cloud.fields.size()));
  for (const TestField& f : cloud.fields) {
    out.string(f.name).u32(f.offset).u8(f.datatype).u32(f.count);
  }
  out.u8(cloud.is_bigendian).u32(cloud.point_step).u32(cloud.row_step);
  out.byte_sequence(cloud.data).u8(cloud.is_dense);
  return out.data();
}

/// A message to write: topic, receive time and serialized bytes.
struct TestMessage {
  std::string topic;
  int64_t time_ns = 0;
  std::vector<uint8_t> data;
};

/// A topic to write: name, ROS 2 type ("sensor_msgs/msg/PointCloud2") and format.
struct TestTopic {
  std::string name;
  std::string type;
  std::string serialization = "cdr";
};

/// A rosbag2 sqlite3 file (schema version 3, as humble writes it).
inline void write_sqlite_bag(const std::filesystem::path& path,
                             const std::vector<TestTopic>& topics,
                             const std::vector<TestMessage>& messages) {
  std::filesystem::remove(path);
  sqlite3* db = nullptr;
  if (sqlite3_open(path.string().c_str(), &db) != SQLITE_OK) throw std::runtime_error("sqlite");
  auto exec = [db](const std::string& sql) {
    if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) {
      throw std::runtime_error(std::string("sqlite: ") + sqlite3_errmsg(db));
    }
  };
  exec("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);");
  exec("INSERT INTO schema VALUES (3, 'humble');");
  exec(
      "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
      "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);");
  exec(
      "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
      "timestamp INTEGER NOT NULL, data BLOB NOT NULL);");
  std::map<std::string, int> ids;
  for (const TestTopic& topic : topics) {
    ids[topic.name] = static_cast<int>(ids.size()) + 1;
    exec("INSERT INTO topics VALUES (" + std::to_string(ids[topic.name]) + ", '" + topic.name +
         "', '" + topic.type + "', '" + topic.serialization + "', '');");
  }
  sqlite3_stmt* insert = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1,
                     &insert, nullptr);
  for (const TestMessage& m : messages) {
    sqlite3_bind_int(insert, 1, ids.at(m.topic));
    sqlite3_bind_int64(insert, 2, m.time_ns);
    sqlite3_bind_blob(insert, 3, m.data.data(), static_cast<int>(m.data.size()), SQLITE_TRANSIENT);
    if (sqlite3_step(insert) != SQLITE_DONE) throw std::runtime_error("sqlite insert");
    sqlite3_reset(insert);
  }
  sqlite3_finalize(insert);
  sqlite3_close(db);
}

/// The metadata.yaml of a bag folder listing `files` (sqlite3 storage unless told).
inline void write_bag_metadata(const std::filesystem::path& folder,
                               const std::vector<std::string>& files,
                               const std::string& storage = "sqlite3") {
  std::ofstream out(folder / "metadata.yaml");
  out << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: " << storage
      << "\n  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n";
  for (const std::string& file : files) out << "    - " << file << "\n";
}

enum class McapCompression { kNone, kZstd, kLz4 };

/// How an MCAP test file is laid out.
struct McapLayoutSpec {
  bool chunked = true;
  McapCompression compression = McapCompression::kNone;
  size_t messages_per_chunk = 2;
  bool summary = true;  ///< schemas, channels, statistics, chunk indexes; else summary_start 0
  std::string message_encoding = "cdr";
  std::string schema_encoding = "ros2msg";
};

/// An MCAP writer after the specification: magic, Header, (Schema, Channel, Message records
/// in chunks or not), DataEnd with the data CRC, summary, Footer with the summary CRC, magic.
class McapTestWriter {
 public:
  explicit McapTestWriter(McapLayoutSpec spec) : spec_(std::move(spec)) {}

  /// Registers a topic of a ROS 2 type (its schema name); returns the channel id.
  uint16_t add_topic(const std::string& topic, const std::string& type) {
    const uint16_t id = static_cast<uint16_t>(channels_.size() + 1);
    channels_.push_back({id, topic, type});
    return id;
  }
  void add_message(uint16_t channel, int64_t log_time_ns, const std::vector<uint8_t>& data) {
    messages_.push_back({channel, log_time_ns, data});
  }

  std::vector<uint8_t> write() const {
    std::vector<uint8_t> file(std::begin(kMagic), std::end(kMagic));
    record(file, 0x01, Bytes().string("ros2").string("featsense-test").out);
    std::vector<uint8_t> definitions;
    for (const Channel& c : channels_) {
      record(definitions, 0x03, schema(c));
      record(definitions, 0x04, channel(c));
    }
    std::vector<uint8_t> chunk_indexes;
    std::map<uint16_t, uint64_t> counts;
    for (const Message& m : messages_) ++counts[m.channel];
    if (!spec_.chunked) {
      file.insert(file.end(), definitions.begin(), definitions.end());
      for (const Message& m : messages_) record(file, 0x05, message(m));
    } else {
      std::vector<uint8_t> inner = definitions;
      size_t in_chunk = 0;
      for (size_t i = 0; i < messages_.size(); ++i) {
        record(inner, 0x05, message(messages_[i]));
        if (++in_chunk == spec_.messages_per_chunk || i + 1 == messages_.size()) {
          write_chunk(file, inner, chunk_indexes);
          inner.clear();
          in_chunk = 0;
        }
      }
      if (messages_.empty()) write_chunk(file, inner, chunk_indexes);
    }
    const uint32_t data_crc = crc(file.data(), file.size());
    record(file, 0x0F, Bytes().u32(data_crc).out);

    uint64_t summary_start = 0;
    std::vector<uint8_t> summary;
    if (spec_.summary) {
      summary_start = file.size();
      for (const Channel& c : channels_) record(summary, 0x03, schema(c));
      for (const Channel& c : channels_) record(summary, 0x04, channel(c));
      Bytes statistics;
      statistics.u64(messages_.size()).u16(static_cast<uint16_t>(channels_.size()));
      statistics.u32(static_cast<uint32_t>(channels_.size())).u32(0).u32(0);
      statistics.u32(static_cast<uint32_t>(chunks_written(chunk_indexes)));
      statistics.u64(messages_.empty() ? 0 : static_cast<uint64_t>(messages_.front().time_ns));
      statistics.u64(messages_.empty() ? 0 : static_cast<uint64_t>(messages_.back().time_ns));
      Bytes map;
      for (const auto& [id, count] : counts) map.u16(id).u64(count);
      statistics.u32(static_cast<uint32_t>(map.out.size())).raw(map.out);
      record(summary, 0x0B, statistics.out);
      summary.insert(summary.end(), chunk_indexes.begin(), chunk_indexes.end());
    }
    file.insert(file.end(), summary.begin(), summary.end());
    Bytes footer;
    footer.u64(summary_start).u64(0);
    std::vector<uint8_t> covered = summary;
    covered.push_back(0x02);
    const uint64_t footer_length = 20;
    for (int i = 0; i < 8; ++i) covered.push_back(static_cast<uint8_t>(footer_length >> (8 * i)));
    covered.insert(covered.end(), footer.out.begin(), footer.out.end());
    footer.u32(spec_.summary ? crc(covered.data(), covered.size()) : 0);
    record(file, 0x02, footer.out);
    file.insert(file.end(), std::begin(kMagic), std::end(kMagic));
    return file;
  }

  static constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

 private:
  struct Channel {
    uint16_t id;
    std::string topic;
    std::string type;
  };
  struct Message {
    uint16_t channel;
    int64_t time_ns;
    std::vector<uint8_t> data;
  };
  struct Bytes {
    std::vector<uint8_t> out;
    Bytes& u8(uint8_t v) { return raw(&v, 1); }
    Bytes& u16(uint16_t v) { return raw(&v, 2); }
    Bytes& u32(uint32_t v) { return raw(&v, 4); }
    Bytes& u64(uint64_t v) { return raw(&v, 8); }
    Bytes& string(const std::string& s) {
      u32(static_cast<uint32_t>(s.size()));
      return raw(s.data(), s.size());
    }
    Bytes& raw(const std::vector<uint8_t>& b) { return raw(b.data(), b.size()); }
    Bytes& raw(const void* p, size_t size) {
      const auto* b = static_cast<const uint8_t*>(p);
      out.insert(out.end(), b, b + size);
      return *this;
    }
  };

  static uint32_t crc(const uint8_t* data, size_t size) {
    return static_cast<uint32_t>(::crc32(0, data, static_cast<uInt>(size)));
  }
  static void record(std::vector<uint8_t>& out, uint8_t opcode, const std::vector<uint8_t>& c) {
    out.push_back(opcode);
    const uint64_t size = c.size();
    for (int i = 0; i < 8; ++i) out.push_back(static_cast<uint8_t>(size >> (8 * i)));
    out.insert(out.end(), c.begin(), c.end());
  }
  std::vector<uint8_t> schema(const Channel& c) const {
    return Bytes().u16(c.id).string(c.type).string(spec_.schema_encoding).string("").out;
  }
  std::vector<uint8_t> channel(const Channel& c) const {
    return Bytes().u16(c.id).u16(c.id).string(c.topic).string(spec_.message_encoding).u32(0).out;
  }
  static std::vector<uint8_t> message(const Message& m) {
    Bytes b;
    b.u16(m.channel).u32(0).u64(static_cast<uint64_t>(m.time_ns));
    b.u64(static_cast<uint64_t>(m.time_ns));
    return b.raw(m.data).out;
  }
  static size_t chunks_written(const std::vector<uint8_t>& chunk_indexes) {
    size_t count = 0;
    for (size_t at = 0; at < chunk_indexes.size(); ++count) {
      uint64_t size = 0;
      std::memcpy(&size, chunk_indexes.data() + at + 1, 8);
      at += 9 + size;
    }
    return count;
  }
  std::vector<uint8_t> compressed(const std::vector<uint8_t>& in) const {
    std::vector<uint8_t> out;
    if (spec_.compression == McapCompression::kZstd) {
      out.resize(ZSTD_compressBound(in.size()));
      const size_t size = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3);
      if (ZSTD_isError(size)) throw std::runtime_error("zstd compression failed");
      out.resize(size);
    } else if (spec_.compression == McapCompression::kLz4) {
      LZ4F_preferences_t preferences{};
      out.resize(LZ4F_compressFrameBound(in.size(), &preferences));
      const size_t size =
          LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), &preferences);
      if (LZ4F_isError(size)) throw std::runtime_error("lz4 compression failed");
      out.resize(size);
    } else {
      out = in;
    }
    return out;
  }
  void write_chunk(std::vector<uint8_t>& file, const std::vector<uint8_t>& inner,
                   std::vector<uint8_t>& chunk_indexes) const {
    const char* names[] = {"", "zstd", "lz4"};
    const std::string name = names[static_cast<int>(spec_.compression)];
    const std::vector<uint8_t> stored = compressed(inner);
    Bytes chunk;
    chunk.u64(0).u64(0).u64(inner.size()).u32(crc(inner.data(), inner.size()));
    chunk.string(name).u64(stored.size()).raw(stored);
    const uint64_t start = file.size();
    record(file, 0x06, chunk.out);
    Bytes index;
    index.u64(0).u64(0).u64(start).u64(file.size() - start).u32(0).u64(0);
    index.string(name).u64(stored.size()).u64(inner.size());
    record(chunk_indexes, 0x08, index.out);
  }

  McapLayoutSpec spec_;
  std::vector<Channel> channels_;
  std::vector<Message> messages_;
};

inline void write_bytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

}  // namespace featsense::test
