// The bag record reader and catalog: the real Ouster bag, bags written by the test writer
// in every compression, and damaged bags.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/file_bytes.hpp"
#include "common/test_data.hpp"
#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_record_reader.hpp"
#include "rosbag/bag_topic_choice.hpp"
#include "slam/rosbag_test_writer.hpp"

namespace featsense::slam {
namespace {

using test::TestBagWriter;
using test::TestCompression;

constexpr TestCompression kAllCompressions[] = {TestCompression::kNone, TestCompression::kBz2,
                                                TestCompression::kLz4};

std::string as_string(const std::vector<uint8_t>& bytes) {
  return std::string(bytes.begin(), bytes.end());
}

struct ReadBack {
  std::vector<BagMessage> messages;  // data copied into payloads
  std::vector<std::vector<uint8_t>> payloads;
  std::vector<std::string> warnings;
  std::map<uint32_t, BagConnection> connections;
  BagWalkStats stats;
  size_t max_buffer_bytes = 0;
};

/// Every message of a bag held in memory, through the streaming reader.
ReadBack read_all(const std::string& bag, BagReadOptions options = {}) {
  ReadBack out;
  options.warn = [&out](const std::string& message) { out.warnings.push_back(message); };
  std::istringstream stream(bag);
  BagRecordReader reader(stream, "test.bag", options);
  while (const std::optional<BagMessage> message = reader.next()) {
    out.messages.push_back(*message);
    out.payloads.emplace_back(message->data.data, message->data.data + message->data.size);
    out.max_buffer_bytes = std::max(out.max_buffer_bytes, reader.buffer_bytes());
  }
  out.connections = reader.connections();
  out.stats = reader.stats();
  return out;
}

/// Messages of distinct sizes and contents, on two connections.
struct WrittenBag {
  std::vector<uint8_t> bytes;
  std::vector<uint32_t> connections;
  std::vector<int64_t> times;
  std::vector<std::vector<uint8_t>> payloads;
  std::vector<uint64_t> chunk_offsets;
};

WrittenBag write_bag(TestCompression compression, bool with_index, int messages = 40,
                     size_t chunk_bytes = 2000) {
  TestBagWriter writer(compression, chunk_bytes);
  const uint32_t points = writer.add_connection("/points", "sensor_msgs/PointCloud2");
  const uint32_t other = writer.add_connection("/other", "std_msgs/String");
  WrittenBag bag;
  for (int i = 0; i < messages; ++i) {
    // Pseudo-random bytes, so that compression keeps the chunks about their size.
    std::vector<uint8_t> payload(static_cast<size_t>(100 + 37 * i));
    uint32_t state = 12345u + static_cast<uint32_t>(i);
    for (uint8_t& byte : payload) {
      state = state * 1664525u + 1013904223u;
      byte = static_cast<uint8_t>(state >> 24);
    }
    const uint32_t connection = i % 3 == 2 ? other : points;
    const int64_t time = 1700000000000000000 + int64_t{i} * 100000000;
    writer.add_message(connection, time, payload);
    bag.connections.push_back(connection);
    bag.times.push_back(time);
    bag.payloads.push_back(payload);
  }
  bag.bytes = writer.finish(with_index);
  bag.chunk_offsets = writer.chunk_offsets();
  return bag;
}

/// The messages read back are the first ones written, unchanged and in order.
void expect_prefix_of(const ReadBack& read, const WrittenBag& written) {
  ASSERT_LE(read.messages.size(), written.payloads.size());
  for (size_t i = 0; i < read.messages.size(); ++i) {
    EXPECT_EQ(read.messages[i].connection, written.connections[i]) << "message " << i;
    EXPECT_EQ(read.messages[i].time_ns, written.times[i]) << "message " << i;
    EXPECT_EQ(read.payloads[i], written.payloads[i]) << "message " << i;
  }
}

// ---------------------------------------------------------------------------------------
// The real Ouster bag

TEST(BagRecordReader, RealOusterBagCatalog) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  std::ifstream stream(path, std::ios::binary);
  const BagCatalog catalog = catalog_bag(stream, path.string());
  // The data README: three topics, raw packets and the metadata string.
  ASSERT_EQ(catalog.topics.size(), 3u);
  const BagTopic* lidar = catalog.find("/os_node0/lidar_packets");
  const BagTopic* imu = catalog.find("/os_node0/imu_packets");
  const BagTopic* metadata = catalog.find("/os_node0/metadata");
  ASSERT_NE(lidar, nullptr);
  ASSERT_NE(imu, nullptr);
  ASSERT_NE(metadata, nullptr);
  EXPECT_EQ(lidar->type, "ouster_ros/PacketMsg");
  EXPECT_EQ(imu->type, "ouster_ros/PacketMsg");
  EXPECT_EQ(metadata->type, "std_msgs/String");
  EXPECT_EQ(classify_topic(*lidar), BagTopicKind::kOusterLidarPackets);
  EXPECT_EQ(classify_topic(*imu), BagTopicKind::kOusterImuPackets);
  EXPECT_EQ(classify_topic(*metadata), BagTopicKind::kOusterMetadata);
  EXPECT_EQ(metadata_topic_for(catalog, *lidar), metadata);
  EXPECT_EQ(&choose_scan_topic(catalog, std::nullopt, "bag"), lidar);
  // The bag format: one uncompressed chunk; the bag was closed, so the index sufficed.
  EXPECT_TRUE(catalog.from_index);
  EXPECT_EQ(catalog.chunks, 1u);
  EXPECT_EQ(catalog.compressions, std::vector<std::string>{"none"});
  EXPECT_TRUE(catalog.warnings.empty());

  // The metadata message parses as the sensor's JSON (newer, nested layout).
  const std::optional<std::string> text =
      read_first_string_message(stream, path.string(), catalog, *metadata);
  ASSERT_TRUE(text.has_value());
  const nlohmann::json json = nlohmann::json::parse(*text);
  for (const char* key : {"beam_intrinsics", "lidar_data_format", "config_params", "sensor_info",
                          "lidar_intrinsics"}) {
    EXPECT_TRUE(json.contains(key)) << key;
  }
  const nlohmann::json& format = json["lidar_data_format"];
  const int columns_per_frame = format["columns_per_frame"].get<int>();
  const int columns_per_packet = format["columns_per_packet"].get<int>();
  const int pixels = format["pixels_per_column"].get<int>();
  EXPECT_EQ(json["config_params"]["lidar_mode"], "512x10");

  // The counts from the index records agree with the messages really there: one whole
  // frame of lidar packets, one metadata message, and 10 IMU packets (counted by an
  // independent parser of the file).
  EXPECT_EQ(lidar->messages, static_cast<uint64_t>(columns_per_frame / columns_per_packet));
  EXPECT_EQ(metadata->messages, 1u);
  EXPECT_EQ(imu->messages, 10u);

  // Streaming every message: the lidar payloads have the packet size of the metadata's
  // profile (RNG15_RFL8_NIR8: 4-byte pixels; PACKET_FORMAT.md), the IMU ones 48 bytes.
  const std::string bag = test::file_bytes(path);
  const ReadBack read = read_all(bag);
  EXPECT_TRUE(read.warnings.empty());
  EXPECT_TRUE(read.stats.reached_end);
  const size_t packet_size =
      32 + static_cast<size_t>(columns_per_packet) * (12 + static_cast<size_t>(pixels) * 4) + 32;
  std::map<std::string, uint64_t> counts;
  for (size_t i = 0; i < read.messages.size(); ++i) {
    const std::string& topic = read.connections.at(read.messages[i].connection).topic;
    ++counts[topic];
    uint32_t buf_size = 0;
    std::memcpy(&buf_size, read.payloads[i].data(), 4);
    if (topic == lidar->name) {
      EXPECT_EQ(buf_size, packet_size);
    } else if (topic == imu->name) {
      EXPECT_EQ(buf_size, 48u);
    }
  }
  EXPECT_EQ(counts[lidar->name], lidar->messages);
  EXPECT_EQ(counts[imu->name], imu->messages);
  EXPECT_EQ(counts[metadata->name], metadata->messages);
}

// ---------------------------------------------------------------------------------------
// Written bags

TEST(BagRecordReader, ReadsBackEveryCompressionWithAndWithoutIndex) {
  for (const TestCompression compression : kAllCompressions) {
    for (const bool with_index : {true, false}) {
      SCOPED_TRACE(std::string(test::compression_name(compression)) +
                   (with_index ? " indexed" : " unindexed"));
      const WrittenBag written = write_bag(compression, with_index);
      ASSERT_GT(written.chunk_offsets.size(), 5u);
      const ReadBack read = read_all(as_string(written.bytes));
      EXPECT_TRUE(read.warnings.empty()) << read.warnings[0];
      EXPECT_TRUE(read.stats.reached_end);
      ASSERT_EQ(read.messages.size(), written.payloads.size());
      expect_prefix_of(read, written);
      ASSERT_EQ(read.connections.size(), 2u);
      EXPECT_EQ(read.connections.at(0).topic, "/points");
      EXPECT_EQ(read.connections.at(0).type, "sensor_msgs/PointCloud2");
      EXPECT_EQ(read.connections.at(1).topic, "/other");
      EXPECT_EQ(read.stats.chunks, written.chunk_offsets.size());
      EXPECT_EQ(read.stats.compressions,
                std::vector<std::string>{test::compression_name(compression)});

      std::istringstream stream(as_string(written.bytes));
      const BagCatalog catalog = catalog_bag(stream, "test.bag");
      EXPECT_EQ(catalog.from_index, with_index);
      ASSERT_EQ(catalog.topics.size(), 2u);
      const uint64_t points = static_cast<uint64_t>(
          std::count(written.connections.begin(), written.connections.end(), 0u));
      EXPECT_EQ(catalog.find("/points")->messages, points);
      EXPECT_EQ(catalog.find("/other")->messages, written.payloads.size() - points);
    }
  }
}

TEST(BagRecordReader, HandsOutOnlyWantedMessages) {
  const WrittenBag written = write_bag(TestCompression::kLz4, true);
  BagReadOptions options;
  options.wanted = [](const BagMessage&, const BagConnection* connection) {
    return connection != nullptr && connection->topic == "/other";
  };
  const ReadBack read = read_all(as_string(written.bytes), options);
  size_t expected = 0;
  for (size_t i = 0; i < written.payloads.size(); ++i) {
    if (written.connections[i] != 1) continue;
    ASSERT_LT(expected, read.messages.size());
    EXPECT_EQ(read.payloads[expected], written.payloads[i]);
    ++expected;
  }
  EXPECT_EQ(read.messages.size(), expected);
  // Every message was still counted.
  EXPECT_EQ(read.stats.message_counts.at(0) + read.stats.message_counts.at(1),
            written.payloads.size());
}

TEST(BagRecordReader, HoldsAboutOneChunkInMemory) {
  // 200 messages of up to 7.5 kB in chunks of about 20 kB.
  const WrittenBag written = write_bag(TestCompression::kLz4, true, 200, 20000);
  ASSERT_GT(written.chunk_offsets.size(), 20u);
  const ReadBack read = read_all(as_string(written.bytes));
  ASSERT_EQ(read.messages.size(), 200u);
  size_t largest_message = 0;
  for (const auto& payload : written.payloads)
    largest_message = std::max(largest_message, payload.size());
  // One uncompressed chunk (threshold + one message + record headers) and its compressed
  // form, with the growth slack of a vector; never the whole bag.
  const size_t chunk_bound = 20000 + largest_message + 1000;
  EXPECT_LT(read.max_buffer_bytes, 4 * chunk_bound);
  EXPECT_LT(read.max_buffer_bytes, written.bytes.size() / 4);
}

/// What rosbag leaves when recording stops without closing the bag: the open chunk's header
/// still holds the place-holder sizes 0 and 0, and its records follow it.
std::vector<uint8_t> with_open_chunk(const WrittenBag& unclosed, TestCompression compression,
                                     const std::vector<std::vector<uint8_t>>& payloads) {
  test::RosBytes records;
  for (const std::vector<uint8_t>& payload : payloads) {
    test::RosBytes header;
    header.field("op", std::vector<uint8_t>{0x02})
        .field("conn", test::le_bytes(uint32_t{0}))
        .field("time", test::time_bytes(1800000000000000000));
    records.raw(test::bag_record(header, payload));
  }
  test::RosBytes chunk_header;
  chunk_header.field("op", std::vector<uint8_t>{0x05})
      .field("compression", std::string(test::compression_name(compression)))
      .field("size", test::le_bytes(uint32_t{0}));
  std::vector<uint8_t> bag = unclosed.bytes;
  const std::vector<uint8_t> open_chunk = test::bag_record(chunk_header, {});
  bag.insert(bag.end(), open_chunk.begin(), open_chunk.end());
  const std::vector<uint8_t> data = test::compress(compression, records.bytes());
  bag.insert(bag.end(), data.begin(), data.end());
  return bag;
}

TEST(BagRecordReader, UnclosedBagWithAnOpenChunk) {
  const std::vector<std::vector<uint8_t>> last = {std::vector<uint8_t>(500, 1),
                                                  std::vector<uint8_t>(700, 2)};
  // Uncompressed: the open chunk's records follow its header as they were written, and
  // are read as records outside a chunk.
  const WrittenBag unclosed = write_bag(TestCompression::kNone, false);
  const ReadBack read =
      read_all(as_string(with_open_chunk(unclosed, TestCompression::kNone, last)));
  EXPECT_TRUE(read.warnings.empty()) << read.warnings[0];
  ASSERT_EQ(read.messages.size(), unclosed.payloads.size() + 2);
  ReadBack closed_part = read;
  closed_part.messages.resize(unclosed.payloads.size());
  closed_part.payloads.resize(unclosed.payloads.size());
  expect_prefix_of(closed_part, unclosed);
  EXPECT_EQ(read.payloads[unclosed.payloads.size()], last[0]);
  EXPECT_EQ(read.payloads[unclosed.payloads.size() + 1], last[1]);

  // Compressed: the open chunk cannot be told apart from junk; the closed chunks are read and
  // a warning says where reading stopped.
  for (const TestCompression compression : {TestCompression::kBz2, TestCompression::kLz4}) {
    SCOPED_TRACE(test::compression_name(compression));
    const WrittenBag compressed = write_bag(compression, false);
    const ReadBack partial = read_all(as_string(with_open_chunk(compressed, compression, last)));
    EXPECT_EQ(partial.messages.size(), compressed.payloads.size());
    expect_prefix_of(partial, compressed);
    ASSERT_EQ(partial.warnings.size(), 1u);
    EXPECT_NE(partial.warnings[0].find("the rest is unreadable"), std::string::npos);
  }
}

// ---------------------------------------------------------------------------------------
// Damaged input

TEST(BagRecordReader, RejectsWhatIsNotABag) {
  auto open = [](const std::string& bytes) {
    std::istringstream stream(bytes);
    BagRecordReader reader(stream, "x.bag");
  };
  EXPECT_THROW(open(""), InputError);
  EXPECT_THROW(open("#ROSBAG V2.0"), InputError);  // no newline: cut inside the version line
  EXPECT_THROW(open("not a bag at all, just some text\n"), InputError);
  try {
    open("#ROSBAG V1.2\nold bag");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("V1.2"), std::string::npos) << e.what();
  }
  // The version line alone is a bag cut off before its first record: nothing to read and a
  // warning, no error (the source decides that nothing readable is an error).
  const ReadBack read = read_all("#ROSBAG V2.0\n");
  EXPECT_TRUE(read.messages.empty());
  EXPECT_EQ(read.warnings.size(), 1u);
}

TEST(BagRecordReader, TruncatedAnywhereGivesAPrefixAndAWarning) {
  for (const TestCompression compression : kAllCompressions) {
    SCOPED_TRACE(test::compression_name(compression));
    const WrittenBag written = write_bag(compression, true, 30, 3000);
    const size_t size = written.bytes.size();
    size_t cut_with_fewer = 0;
    for (size_t cut = 13; cut < size; cut += (cut < 4200 ? 509 : 97)) {
      SCOPED_TRACE("cut at " + std::to_string(cut));
      const std::string bag = as_string(written.bytes).substr(0, cut);
      const ReadBack read = read_all(bag);
      expect_prefix_of(read, written);
      if (read.messages.size() < written.payloads.size()) {
        ++cut_with_fewer;
        EXPECT_FALSE(read.warnings.empty());
      }
      std::istringstream stream(bag);
      EXPECT_NO_THROW(catalog_bag(stream, "cut.bag"));
    }
    EXPECT_GT(cut_with_fewer, 10u);
  }
}

/// The byte offset of a header field's value in a record starting at `record`.
size_t field_value_offset(const std::vector<uint8_t>& bytes, size_t record,
                          const std::string& name) {
  const std::string bag = as_string(bytes);
  const size_t at = bag.find(name + "=", record);
  EXPECT_NE(at, std::string::npos);
  return at + name.size() + 1;
}

void put_u32(std::vector<uint8_t>& bytes, size_t offset, uint32_t value) {
  std::memcpy(bytes.data() + offset, &value, 4);
}

TEST(BagRecordReader, ChunkWhoseDeclaredSizeLies) {
  for (const TestCompression compression : kAllCompressions) {
    SCOPED_TRACE(test::compression_name(compression));
    const WrittenBag written = write_bag(compression, true, 12, 1000000);  // one chunk
    ASSERT_EQ(written.chunk_offsets.size(), 1u);
    const size_t size_at = field_value_offset(written.bytes, written.chunk_offsets[0], "size");
    uint32_t declared = 0;
    std::memcpy(&declared, written.bytes.data() + size_at, 4);

    // Larger than the truth: every message still comes out, with a warning.
    std::vector<uint8_t> larger = written.bytes;
    put_u32(larger, size_at, declared + 5000);
    const ReadBack from_larger = read_all(as_string(larger));
    EXPECT_EQ(from_larger.messages.size(), written.payloads.size());
    expect_prefix_of(from_larger, written);
    EXPECT_FALSE(from_larger.warnings.empty());

    // Smaller than the truth: for compressed chunks the messages in the declared part come
    // out (the uncompressed chunk's data length is the truth there); always a warning.
    std::vector<uint8_t> smaller = written.bytes;
    put_u32(smaller, size_at, declared / 2);
    const ReadBack from_smaller = read_all(as_string(smaller));
    expect_prefix_of(from_smaller, written);
    EXPECT_FALSE(from_smaller.warnings.empty());
    if (compression != TestCompression::kNone) {
      EXPECT_LT(from_smaller.messages.size(), written.payloads.size());
      EXPECT_GT(from_smaller.messages.size(), 0u);
    }

    // Absurd: beyond the 1 GiB limit, skipped without allocating it.
    std::vector<uint8_t> absurd = written.bytes;
    put_u32(absurd, size_at, 0xFFFFFFF0u);
    const ReadBack from_absurd = read_all(as_string(absurd));
    EXPECT_TRUE(from_absurd.messages.empty());
    EXPECT_FALSE(from_absurd.warnings.empty());
    EXPECT_LT(from_absurd.max_buffer_bytes, 1u << 20);
  }
}

TEST(BagRecordReader, HeaderFieldLengthPastTheRecord) {
  const WrittenBag written = write_bag(TestCompression::kNone, true, 12, 1000000);
  // Inside the chunk: the `conn` field of the second message's header claims 200 bytes.
  std::vector<uint8_t> bytes = written.bytes;
  const std::string bag = as_string(bytes);
  size_t first_message = bag.find(std::string("op=\x02", 4), written.chunk_offsets[0]);
  const size_t second_message = bag.find(std::string("op=\x02", 4), first_message + 4);
  const size_t conn_field = bag.find("conn=", second_message);
  ASSERT_NE(conn_field, std::string::npos);
  put_u32(bytes, conn_field - 4, 200);
  const ReadBack read = read_all(as_string(bytes));
  ASSERT_EQ(read.messages.size(), written.payloads.size() - 1);
  EXPECT_EQ(read.payloads[0], written.payloads[0]);
  EXPECT_EQ(read.payloads[1], written.payloads[2]);
  ASSERT_EQ(read.warnings.size(), 1u);
  EXPECT_NE(read.warnings[0].find("claims 200 bytes"), std::string::npos) << read.warnings[0];

  // At the top level: the bag header's first field runs past its header; the record is
  // skipped and the chunks after it are read.
  std::vector<uint8_t> top = written.bytes;
  put_u32(top, 13 + 4, 100000);
  const ReadBack read_top = read_all(as_string(top));
  EXPECT_EQ(read_top.messages.size(), written.payloads.size());
  ASSERT_EQ(read_top.warnings.size(), 2u);  // and at the end: no bag header was read
  EXPECT_NE(read_top.warnings[0].find("claims 100000 bytes"), std::string::npos);

  // A record header length past the end of the file: the rest is unreadable.
  std::vector<uint8_t> huge = written.bytes;
  put_u32(huge, written.chunk_offsets[0], 0x7FFFFFFFu);
  const ReadBack read_huge = read_all(as_string(huge));
  EXPECT_TRUE(read_huge.messages.empty());
  EXPECT_EQ(read_huge.warnings.size(), 1u);
}

TEST(BagRecordReader, CorruptCompressedDataAndUnknownCompression) {
  for (const TestCompression compression : {TestCompression::kBz2, TestCompression::kLz4}) {
    SCOPED_TRACE(test::compression_name(compression));
    const WrittenBag written = write_bag(compression, true, 30, 3000);
    ASSERT_GE(written.chunk_offsets.size(), 3u);
    // Overwrite the middle of the second chunk's compressed data with junk.
    std::vector<uint8_t> bytes = written.bytes;
    const size_t start = written.chunk_offsets[1];
    const size_t end = written.chunk_offsets[2];
    for (size_t i = start + (end - start) / 2; i < start + (end - start) / 2 + 64; ++i) {
      bytes[i] = static_cast<uint8_t>(i * 31);
    }
    const ReadBack read = read_all(as_string(bytes));
    EXPECT_FALSE(read.warnings.empty());
    // The chunks before and after the damage are whole.
    EXPECT_EQ(read.payloads.front(), written.payloads.front());
    EXPECT_EQ(read.payloads.back(), written.payloads.back());
  }
  const WrittenBag written = write_bag(TestCompression::kLz4, true, 30, 3000);
  std::vector<uint8_t> bytes = written.bytes;
  const size_t name_at = field_value_offset(bytes, written.chunk_offsets[0], "compression");
  bytes[name_at] = 'x';  // "xz4"
  const ReadBack read = read_all(as_string(bytes));
  ASSERT_EQ(read.warnings.size(), 1u);
  EXPECT_NE(read.warnings[0].find("unknown compression 'xz4'"), std::string::npos);
  EXPECT_LT(read.messages.size(), written.payloads.size());
  EXPECT_EQ(read.payloads.back(), written.payloads.back());
}

}  // namespace
}  // namespace featsense::slam
