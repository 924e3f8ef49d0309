#pragma once
/// The records of an MCAP file (mcap.dev/spec, format version 0): each is an opcode (u8), a
/// content length (u64) and the content. Integers are little-endian; strings are u32 length +
/// UTF-8; byte arrays, maps and arrays have their byte length first (u32, except the u64 of a
/// chunk's records and an attachment's data). Bytes after the fields a record defines are
/// skipped (the spec lets writers append fields), so parsers read only what they know.

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

enum class McapOpcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// The record's name in the spec ("Chunk"), or "opcode 0xNN" for one it does not define.
std::string to_string(McapOpcode opcode);

/// A record whose content ends before one of its fields; the message names the field.
class McapFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using McapStringMap = std::map<std::string, std::string>;

struct McapHeader {
  std::string profile;
  std::string library;
};

struct McapFooter {
  uint64_t summary_start = 0;  ///< 0 where the file has no summary section
  uint64_t summary_offset_start = 0;
  uint32_t summary_crc = 0;  ///< 0 where not written
};

struct McapSchema {
  uint16_t id = 0;
  std::string name;      ///< the message type, e.g. "sensor_msgs/msg/PointCloud2"
  std::string encoding;  ///< "ros2msg", "ros1msg", ...
  ByteView data;
};

struct McapChannel {
  uint16_t id = 0;
  uint16_t schema_id = 0;  ///< 0: schemaless
  std::string topic;
  std::string message_encoding;  ///< "cdr", "ros1", ...
  McapStringMap metadata;
};

struct McapMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;  ///< ns
  uint64_t publish_time = 0;
  ByteView data;
};

struct McapChunk {
  uint64_t message_start_time = 0;
  uint64_t message_end_time = 0;
  uint64_t uncompressed_size = 0;
  uint32_t uncompressed_crc = 0;  ///< 0 where not written
  std::string compression;        ///< "", "zstd" or "lz4"
  ByteView records;
};

struct McapMessageIndex {
  uint16_t channel_id = 0;
  std::vector<std::pair<uint64_t, uint64_t>> records;  ///< (log_time, offset in the chunk)
};

struct McapChunkIndex {
  uint64_t message_start_time = 0;
  uint64_t message_end_time = 0;
  uint64_t chunk_start_offset = 0;
  uint64_t chunk_length = 0;
  std::map<uint16_t, uint64_t> message_index_offsets;
  uint64_t message_index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0;
  uint64_t uncompressed_size = 0;
};

struct McapAttachment {
  uint64_t log_time = 0;
  uint64_t create_time = 0;
  std::string name;
  std::string media_type;
  ByteView data;
  uint32_t crc = 0;      ///< of the fields before it; 0 where not written
  ByteView crc_covered;  ///< the bytes the crc covers
};

struct McapAttachmentIndex {
  uint64_t offset = 0;
  uint64_t length = 0;
  uint64_t log_time = 0;
  uint64_t create_time = 0;
  uint64_t data_size = 0;
  std::string name;
  std::string media_type;
};

struct McapStatistics {
  uint64_t message_count = 0;
  uint16_t schema_count = 0;
  uint32_t channel_count = 0;
  uint32_t attachment_count = 0;
  uint32_t metadata_count = 0;
  uint32_t chunk_count = 0;
  uint64_t message_start_time = 0;
  uint64_t message_end_time = 0;
  std::map<uint16_t, uint64_t> channel_message_counts;
};

struct McapMetadata {
  std::string name;
  McapStringMap metadata;
};

struct McapMetadataIndex {
  uint64_t offset = 0;
  uint64_t length = 0;
  std::string name;
};

struct McapSummaryOffset {
  uint8_t group_opcode = 0;
  uint64_t group_start = 0;
  uint64_t group_length = 0;
};

struct McapDataEnd {
  uint32_t data_section_crc = 0;  ///< 0 where not written
};

/// Parsers of a record's content (the bytes after opcode and length). They throw
/// McapFormatError naming the field that runs past the end; views point into `content`.
McapHeader parse_mcap_header(ByteView content);
McapFooter parse_mcap_footer(ByteView content);
McapSchema parse_mcap_schema(ByteView content);
McapChannel parse_mcap_channel(ByteView content);
McapMessage parse_mcap_message(ByteView content);
McapChunk parse_mcap_chunk(ByteView content);
McapMessageIndex parse_mcap_message_index(ByteView content);
McapChunkIndex parse_mcap_chunk_index(ByteView content);
McapAttachment parse_mcap_attachment(ByteView content);
McapAttachmentIndex parse_mcap_attachment_index(ByteView content);
McapStatistics parse_mcap_statistics(ByteView content);
McapMetadata parse_mcap_metadata(ByteView content);
McapMetadataIndex parse_mcap_metadata_index(ByteView content);
McapSummaryOffset parse_mcap_summary_offset(ByteView content);
McapDataEnd parse_mcap_data_end(ByteView content);

}  // namespace featsense::slam
