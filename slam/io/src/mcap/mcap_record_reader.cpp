#include "mcap/mcap_record_reader.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstring>

#include "featsense/slam/scan_source.hpp"
#include "rosbag/chunk_decompress.hpp"
#include "stream_size.hpp"

namespace featsense::slam {
namespace {

/// Opcode (u8) + content length (u64).
constexpr uint64_t kRecordPrefixBytes = 9;
/// The Footer's fields that its summary_crc covers: summary_start and summary_offset_start.
constexpr uint64_t kFooterCrcFieldBytes = 16;

uint32_t crc32_of(uint32_t crc, const uint8_t* data, uint64_t size) {
  while (size > 0) {
    const uInt step = static_cast<uInt>(std::min<uint64_t>(size, 1u << 30));
    crc = static_cast<uint32_t>(::crc32(crc, data, step));
    data += step;
    size -= step;
  }
  return crc;
}

std::optional<ChunkCompression> mcap_compression(const std::string& name) {
  if (name.empty()) return ChunkCompression::kNone;
  if (name == "zstd") return ChunkCompression::kZstd;
  if (name == "lz4") return ChunkCompression::kLz4;
  return std::nullopt;
}

std::string hex32(uint32_t value) {
  char text[12];
  std::snprintf(text, sizeof text, "%08x", value);
  return text;
}

}  // namespace

McapRecordReader::McapRecordReader(std::istream& stream, std::string origin,
                                   McapReadOptions options)
    : stream_(stream), origin_(std::move(origin)), options_(std::move(options)) {
  file_size_ = nonempty_stream_size(stream_, origin_);
  uint8_t magic[sizeof kMcapMagic] = {};
  if (!read_exactly(magic, std::min<uint64_t>(sizeof magic, file_size_)) ||
      std::memcmp(magic, kMcapMagic, sizeof magic) != 0) {
    throw InputError(origin_ + ": not an MCAP file (it does not start with the MCAP magic)");
  }
  data_crc_ = crc32_of(0, magic, sizeof magic);
  offset_ = sizeof kMcapMagic;
}

void McapRecordReader::jump_to(uint64_t offset) {
  in_chunk_ = false;
  finished_ = false;
  sequential_ = false;
  summary_from_.reset();
  footer_.reset();
  offset_ = offset;
  stream_.clear();
  stream_.seekg(static_cast<std::streamoff>(offset));
}

std::optional<McapRecord> McapRecordReader::next() {
  while (!finished_ || in_chunk_) {
    if (in_chunk_) {
      if (std::optional<McapRecord> record = next_in_chunk()) return record;
      continue;
    }
    if (std::optional<McapRecord> record = next_top_level()) return record;
  }
  return std::nullopt;
}

std::optional<McapRecord> McapRecordReader::next_top_level() {
  const uint64_t record_offset = offset_;
  const uint64_t left = file_size_ - offset_;
  if (footer_) {
    // After the Footer only the closing magic may follow.
    uint8_t magic[sizeof kMcapMagic] = {};
    if (left != sizeof magic || !read_exactly(magic, sizeof magic) ||
        std::memcmp(magic, kMcapMagic, sizeof magic) != 0) {
      warn(at(record_offset) + ": the Footer is not followed by the closing magic and the end");
    }
    finished_ = true;
    return std::nullopt;
  }
  if (left < kRecordPrefixBytes) {
    warn(at(record_offset) + ": the file ends " +
         (left == 0 ? std::string("without a Footer")
                    : "with " + std::to_string(left) + " stray bytes instead of a Footer") +
         " (a recording that was cut off?)");
    finished_ = true;
    return std::nullopt;
  }
  uint8_t prefix[kRecordPrefixBytes];
  if (!read_exactly(prefix, sizeof prefix)) return std::nullopt;
  const auto opcode = static_cast<McapOpcode>(prefix[0]);
  const uint64_t length = load_le<uint64_t>(prefix + 1);
  const uint64_t available = left - kRecordPrefixBytes;
  if (length > available) {
    warn(at(record_offset) + ": " + to_string(opcode) + " record claims " + std::to_string(length) +
         " bytes but only " + std::to_string(available) +
         " remain (a recording that was cut off?)");
    finished_ = true;
    return std::nullopt;
  }
  offset_ = record_offset + kRecordPrefixBytes + length;
  if (length > options_.max_record_bytes) {
    warn(at(record_offset) + ": " + to_string(opcode) + " record of " + std::to_string(length) +
         " bytes is larger than the limit of " + std::to_string(options_.max_record_bytes) +
         "; skipped");
    sequential_ = false;
    stream_.seekg(static_cast<std::streamoff>(offset_));
    return next_top_level();
  }
  data_crc_before_record_ = data_crc_;
  if (sequential_) {
    data_crc_ = crc32_of(data_crc_, prefix, sizeof prefix);
    if (summary_from_) summary_crc_ = crc32_of(summary_crc_, prefix, sizeof prefix);
  }
  summary_crc_before_record_ = summary_crc_;
  const bool skip_chunk = opcode == McapOpcode::kChunk && !options_.expand_chunks;
  if (skip_chunk) {
    // Only the fields before the records, which the Chunk's parser needs.
    sequential_ = false;
    const uint64_t fields = std::min<uint64_t>(length, 8 * 3 + 4 + 4 + 64 + 8);
    record_.resize(static_cast<size_t>(fields));
    if (!read_exactly(record_.data(), fields)) return std::nullopt;
    stream_.seekg(static_cast<std::streamoff>(offset_));
    return McapRecord{opcode, {record_.data(), record_.size()}, record_offset, false};
  }
  record_.resize(static_cast<size_t>(length));
  if (!read_exactly(record_.data(), length)) return std::nullopt;
  if (sequential_) {
    data_crc_ = crc32_of(data_crc_, record_.data(), length);
    if (summary_from_) summary_crc_ = crc32_of(summary_crc_, record_.data(), length);
  }
  McapRecord record{opcode, {record_.data(), record_.size()}, record_offset, false};
  check_crcs(record);
  if (opcode == McapOpcode::kChunk) open_chunk(record);
  return record;
}

void McapRecordReader::check_crcs(const McapRecord& record) {
  const ByteView& content = record.content;
  try {
    switch (record.opcode) {
      case McapOpcode::kDataEnd: {
        const uint32_t expected = parse_mcap_data_end(content).data_section_crc;
        // The data section CRC covers everything before the DataEnd record.
        if (sequential_ && expected != 0 && expected != data_crc_before_record_) {
          warn(at(record.offset) + ": data section CRC is " + hex32(data_crc_before_record_) +
               ", the DataEnd record says " + hex32(expected) + " (damaged data)");
        }
        summary_from_ = offset_;
        summary_crc_ = 0;
        break;
      }
      case McapOpcode::kFooter: {
        const McapFooter footer = parse_mcap_footer(content);
        footer_ = footer;
        if (sequential_ && summary_from_ && footer.summary_crc != 0 &&
            footer.summary_start == *summary_from_ && content.size >= kFooterCrcFieldBytes) {
          // summary_crc_ already holds the footer's prefix and all of its content; start
          // again from the part before the Footer's content and add its two u64 fields.
          const uint32_t crc =
              crc32_of(summary_crc_before_record_, content.data, kFooterCrcFieldBytes);
          if (crc != footer.summary_crc) {
            warn(at(record.offset) + ": summary CRC is " + hex32(crc) + ", the Footer says " +
                 hex32(footer.summary_crc) + " (damaged summary)");
          }
        }
        break;
      }
      case McapOpcode::kAttachment: {
        const McapAttachment attachment = parse_mcap_attachment(content);
        if (attachment.crc != 0) {
          const uint32_t crc =
              crc32_of(0, attachment.crc_covered.data, attachment.crc_covered.size);
          if (crc != attachment.crc) {
            warn(at(record.offset) + ": attachment '" + attachment.name + "' CRC is " + hex32(crc) +
                 ", the record says " + hex32(attachment.crc) + " (damaged data)");
          }
        }
        break;
      }
      default:
        break;
    }
  } catch (const McapFormatError& e) {
    warn(at(record.offset) + ": " + e.what());
  }
}

void McapRecordReader::open_chunk(const McapRecord& record) {
  McapChunk chunk;
  try {
    chunk = parse_mcap_chunk(record.content);
  } catch (const McapFormatError& e) {
    warn(at(record.offset) + ": " + e.what() + "; chunk skipped");
    return;
  }
  const std::optional<ChunkCompression> compression = mcap_compression(chunk.compression);
  if (!compression) {
    warn(at(record.offset) + ": chunk with unknown compression '" +
         chunk.compression.substr(0, 16) + "'; skipped");
    return;
  }
  if (chunk.uncompressed_size > options_.max_record_bytes) {
    warn(at(record.offset) + ": chunk of " + std::to_string(chunk.uncompressed_size) +
         " bytes uncompressed is larger than the limit; skipped");
    return;
  }
  const ChunkDecompression result = decompress_chunk(
      *compression, chunk.records, static_cast<size_t>(chunk.uncompressed_size), chunk_);
  if (result.status != ChunkDecompression::Status::kComplete) {
    warn(at(record.offset) + ": " + (chunk.compression.empty() ? "" : chunk.compression + " ") +
         "chunk " + result.problem + "; skipped");
    return;
  }
  if (chunk.uncompressed_crc != 0) {
    const uint32_t crc = crc32_of(0, chunk_.data(), result.size);
    if (crc != chunk.uncompressed_crc) {
      warn(at(record.offset) + ": chunk CRC is " + hex32(crc) + ", the record says " +
           hex32(chunk.uncompressed_crc) + " (damaged chunk); skipped");
      return;
    }
  }
  chunk_size_ = result.size;
  chunk_pos_ = 0;
  chunk_offset_ = record.offset;
  in_chunk_ = true;
}

std::optional<McapRecord> McapRecordReader::next_in_chunk() {
  const size_t left = chunk_size_ - chunk_pos_;
  if (left == 0) {
    in_chunk_ = false;
    return std::nullopt;
  }
  if (left < kRecordPrefixBytes) {
    warn(at(chunk_offset_) + ": chunk ends with " + std::to_string(left) +
         " stray bytes after its last record");
    in_chunk_ = false;
    return std::nullopt;
  }
  const uint8_t* prefix = chunk_.data() + chunk_pos_;
  const auto opcode = static_cast<McapOpcode>(prefix[0]);
  const uint64_t length = load_le<uint64_t>(prefix + 1);
  if (length > left - kRecordPrefixBytes) {
    warn(at(chunk_offset_) + ": " + to_string(opcode) + " record at byte " +
         std::to_string(chunk_pos_) + " of the chunk claims " + std::to_string(length) +
         " bytes, more than the chunk holds; rest of the chunk skipped");
    in_chunk_ = false;
    return std::nullopt;
  }
  McapRecord record{
      opcode, {prefix + kRecordPrefixBytes, static_cast<size_t>(length)}, chunk_offset_, true};
  chunk_pos_ += static_cast<size_t>(kRecordPrefixBytes + length);
  return record;
}

bool McapRecordReader::read_exactly(uint8_t* out, uint64_t size) {
  stream_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(size));
  if (static_cast<uint64_t>(stream_.gcount()) != size) {
    warn(at(offset_) + ": read error");
    finished_ = true;
    return false;
  }
  return true;
}

void McapRecordReader::warn(const std::string& message) {
  ++warnings_;
  if (options_.warn) options_.warn(message);
}

std::string McapRecordReader::at(uint64_t offset) const {
  return origin_ + " at offset " + std::to_string(offset);
}

}  // namespace featsense::slam
