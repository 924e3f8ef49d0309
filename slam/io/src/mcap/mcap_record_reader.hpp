#pragma once
/// A streaming reader of MCAP files: the records in file order, with the records inside each
/// chunk handed out in its place (decompressed one chunk at a time: none, zstd, lz4). It
/// needs no summary or index, so it also reads a recording that was cut off. Lengths are
/// checked against the bytes really there before anything is allocated; CRCs that a writer
/// filled in (chunk, attachment, data section, summary) are checked.

#include <cstdint>
#include <functional>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "mcap/mcap_records.hpp"
#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

/// The 8 bytes at both ends of an MCAP file.
inline constexpr uint8_t kMcapMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

/// One record; `content` stays valid until the reader's next call.
struct McapRecord {
  McapOpcode opcode = McapOpcode::kHeader;
  ByteView content;
  uint64_t offset = 0;    ///< file offset of the record, or of the chunk that holds it
  bool in_chunk = false;  ///< read from inside a chunk
};

struct McapReadOptions {
  /// True: after each Chunk record, the records inside it. False: chunks are handed out
  /// whole and their contents skipped.
  bool expand_chunks = true;
  /// Larger records (and chunks, compressed or not) are skipped with a warning, bytes.
  uint64_t max_record_bytes = uint64_t{1} << 30;
  /// Receives each warning (damage, CRC mismatches, a missing end); unset: only counted.
  std::function<void(const std::string&)> warn;
};

class McapRecordReader {
 public:
  /// Checks the leading magic. `stream` must be seekable and outlive the reader; `origin`
  /// names it in messages. Throws InputError when it is not an MCAP file.
  McapRecordReader(std::istream& stream, std::string origin, McapReadOptions options = {});

  /// The next record in file order, or nullopt after the Footer (and the trailing magic) or
  /// at damage that ends the readable data (reported through the warning callback).
  std::optional<McapRecord> next();

  /// Continues with the top-level record at `offset` (a summary section); CRCs of the data
  /// and summary sections are no longer checked.
  void jump_to(uint64_t offset);

  uint64_t file_size() const { return file_size_; }
  uint64_t warnings() const { return warnings_; }
  /// True once the Footer was read.
  bool reached_footer() const { return footer_.has_value(); }
  const std::optional<McapFooter>& footer() const { return footer_; }

 private:
  std::optional<McapRecord> next_top_level();
  std::optional<McapRecord> next_in_chunk();
  void open_chunk(const McapRecord& record);
  bool read_exactly(uint8_t* out, uint64_t size);
  void check_crcs(const McapRecord& record);
  void warn(const std::string& message);
  std::string at(uint64_t offset) const;

  std::istream& stream_;
  std::string origin_;
  McapReadOptions options_;
  uint64_t file_size_ = 0;
  uint64_t offset_ = 0;  ///< of the next top-level record
  bool finished_ = false;
  uint64_t warnings_ = 0;
  std::vector<uint8_t> record_;  ///< content of the current top-level record
  std::vector<uint8_t> chunk_;   ///< the current chunk's records, decompressed
  size_t chunk_size_ = 0;        ///< bytes of chunk_ that hold them
  size_t chunk_pos_ = 0;
  uint64_t chunk_offset_ = 0;
  bool in_chunk_ = false;
  /// Running CRC-32 of every byte read in order from the start, while nothing was skipped.
  bool sequential_ = true;
  uint32_t data_crc_ = 0;
  uint32_t data_crc_before_record_ = 0;  ///< of the bytes before the current record
  /// Running CRC-32 from the end of DataEnd, the start of a summary section.
  std::optional<uint64_t> summary_from_;
  uint32_t summary_crc_ = 0;
  uint32_t summary_crc_before_record_ = 0;  ///< through the current record's prefix
  std::optional<McapFooter> footer_;
};

}  // namespace featsense::slam
