#pragma once
/// A streaming reader of ROS1 bags (format 2.0) that walks the records in file order,
/// decompressing one chunk at a time. It needs no index, so it also reads a bag whose index
/// is missing (a recording that was cut off). Every length read from the file is checked
/// against the bytes really there before anything is allocated or read.

#include <cstdint>
#include <functional>
#include <istream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rosbag/bag_record_header.hpp"
#include "rosbag/chunk_decompress.hpp"
#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

/// A connection record: which topic and message type a connection id stands for.
struct BagConnection {
  uint32_t id = 0;
  std::string topic;
  std::string type;  ///< e.g. "sensor_msgs/PointCloud2"
  std::string md5sum;
  std::string message_definition;
};

/// One message record.
struct BagMessage {
  uint32_t connection = 0;
  int64_t time_ns = 0;  ///< when the recorder received it, ns since the epoch
  ByteView data;        ///< the serialized message; valid until the reader's next call
  uint64_t offset = 0;  ///< file offset of the record, or of the chunk that holds it
};

/// The fields of the bag header record (op 0x03).
struct BagHeaderInfo {
  bool present = false;
  uint64_t index_pos = 0;  ///< file offset of the index; 0 where the bag was never closed
  uint32_t conn_count = 0;
  uint32_t chunk_count = 0;
};

struct BagReadOptions {
  /// True: decompress chunks and hand out the messages inside. False: walk only the
  /// top-level records, skipping chunk data unread (cheap; enough for a bag that was closed
  /// properly, whose connections and per-connection counts sit outside the chunks).
  bool read_chunks = true;
  /// Which messages to hand out; the others are counted and passed over without a copy.
  /// `connection` is nullptr where no connection record for the id has been met. Unset:
  /// every message.
  std::function<bool(const BagMessage& message, const BagConnection* connection)> wanted;
  /// Larger chunks (uncompressed or compressed) are skipped with a warning, bytes.
  uint64_t max_chunk_bytes = uint64_t{1} << 30;
  /// Receives each warning (damaged or skipped records); unset: warnings are only counted.
  std::function<void(const std::string&)> warn;
};

/// What a walk met, for the catalog and for tests.
struct BagWalkStats {
  uint64_t chunks = 0;
  std::vector<std::string> compressions;        ///< each name once, in order of meeting
  std::map<uint32_t, uint64_t> message_counts;  ///< messages met per connection id
  std::map<uint32_t, uint64_t> index_counts;    ///< per connection from index records
  uint64_t top_level_connections = 0;           ///< connection records outside chunks
  uint64_t warnings = 0;
  bool reached_end = false;  ///< the walk ended exactly at the end of the file
};

class BagRecordReader {
 public:
  /// Checks the version line. `stream` must be seekable and outlive the reader; `origin`
  /// names it in messages. Throws InputError when it is not a bag of format 2.0.
  BagRecordReader(std::istream& stream, std::string origin, BagReadOptions options = {});

  /// The next wanted message in file order, or nullopt at the end of the readable data.
  /// Damage is reported through the warning callback; reading goes on where it can.
  std::optional<BagMessage> next();

  /// Connections met so far (plus any added), by id.
  const std::map<uint32_t, BagConnection>& connections() const { return connections_; }
  /// Makes a connection known before its record is met (from an earlier pass).
  void add_connection(const BagConnection& connection);

  const BagHeaderInfo& header() const { return header_; }
  const BagWalkStats& stats() const { return stats_; }
  uint64_t file_size() const { return file_size_; }
  /// Bytes the reader's buffers hold (at most about one chunk compressed + uncompressed).
  size_t buffer_bytes() const { return chunk_.capacity() + record_.capacity(); }

 private:
  /// Reads one top-level record; may start a chunk or yield a message. False at the end.
  bool read_top_level(std::optional<BagMessage>& message);
  void read_chunk(const BagRecordHeader& header, uint64_t record_offset, uint64_t data_size,
                  uint64_t available);
  std::optional<BagMessage> next_in_chunk();
  void read_connection(const BagRecordHeader& header, ByteView data, uint64_t offset);
  bool read_bytes(std::vector<uint8_t>& buffer, uint64_t size);
  void skip_to(uint64_t offset);
  void warn(const std::string& message);
  std::string at(uint64_t offset) const;
  /// A message record's header as a BagMessage (data not yet attached), counted per
  /// connection; nullopt when the options' filter does not want it.
  std::optional<BagMessage> count_and_filter(const BagRecordHeader& header, uint64_t offset);

  std::istream& stream_;
  std::string origin_;
  BagReadOptions options_;
  uint64_t file_size_ = 0;
  uint64_t offset_ = 0;  ///< where the stream stands
  bool finished_ = false;

  BagHeaderInfo header_;
  std::map<uint32_t, BagConnection> connections_;
  BagWalkStats stats_;

  std::vector<uint8_t> header_bytes_;
  std::vector<uint8_t> record_;  ///< top-level record data (compressed chunk, message)
  std::vector<uint8_t> chunk_;   ///< the current chunk, uncompressed
  size_t chunk_size_ = 0;        ///< bytes of chunk_ in use
  size_t chunk_cursor_ = 0;      ///< next record inside the chunk
  uint64_t chunk_offset_ = 0;    ///< file offset of the current chunk record
  bool in_chunk_ = false;
};

}  // namespace featsense::slam
