#include "rosbag/bag_record_reader.hpp"

#include <algorithm>
#include <string_view>

#include "featsense/slam/scan_source.hpp"
#include "stream_size.hpp"

namespace featsense::slam {
namespace {

constexpr std::string_view kVersionLine = "#ROSBAG V2.0\n";
/// Record headers hold a handful of short fields; a longer one means a corrupt length.
constexpr uint32_t kMaxHeaderBytes = 1u << 20;
/// Compression names are kept for the source's description; junk ones are cut short.
constexpr size_t kMaxCompressionNameBytes = 16;

}  // namespace

BagRecordReader::BagRecordReader(std::istream& stream, std::string origin, BagReadOptions options)
    : stream_(stream), origin_(std::move(origin)), options_(std::move(options)) {
  file_size_ = nonempty_stream_size(stream_, origin_);

  std::string line(kVersionLine.size(), '\0');
  stream_.read(line.data(), static_cast<std::streamsize>(line.size()));
  line.resize(static_cast<size_t>(stream_.gcount()));
  if (line != kVersionLine) {
    if (line.compare(0, 8, "#ROSBAG ") == 0) {
      throw InputError(origin_ + ": bag format '" + line.substr(8, line.find('\n') - 8) +
                       "' is not supported (only ROS1 bags, format 2.0)");
    }
    throw InputError(origin_ + ": not a ROS bag (it does not start with '#ROSBAG V2.0')");
  }
  offset_ = kVersionLine.size();
}

void BagRecordReader::add_connection(const BagConnection& connection) {
  connections_.emplace(connection.id, connection);
}

std::optional<BagMessage> BagRecordReader::next() {
  for (;;) {
    if (in_chunk_) {
      if (std::optional<BagMessage> message = next_in_chunk()) return message;
      continue;
    }
    if (finished_) return std::nullopt;
    std::optional<BagMessage> message;
    if (!read_top_level(message)) finished_ = true;
    if (message) return message;
  }
}

bool BagRecordReader::read_top_level(std::optional<BagMessage>& message) {
  const uint64_t record_offset = offset_;
  const uint64_t left = file_size_ - offset_;
  if (left == 0) {
    // A bag that was closed says where its index starts; ending before it means cut off.
    // (An unclosed bag says 0 and may end after any record.)
    if (!header_.present) {
      warn(at(record_offset) + ": the file ends without a bag header record (cut off?)");
    } else if (header_.index_pos >= file_size_) {
      warn(at(record_offset) + ": the file ends before the index that the bag header places at " +
           std::to_string(header_.index_pos) + " (cut off?)");
    }
    stats_.reached_end = true;
    return false;
  }
  if (left < 8) {
    warn(at(record_offset) + ": the file ends with " + std::to_string(left) +
         " stray bytes (cut off?)");
    return false;
  }
  if (!read_bytes(header_bytes_, 4)) return false;
  const uint32_t header_size = load_le<uint32_t>(header_bytes_.data());
  if (header_size > left - 8 || header_size > kMaxHeaderBytes) {
    warn(at(record_offset) + ": header length " + std::to_string(header_size) +
         " runs past the end of the file or is absurd (" + std::to_string(left) +
         " bytes left); the rest is unreadable");
    return false;
  }
  if (!read_bytes(header_bytes_, uint64_t{header_size} + 4)) return false;
  const uint32_t data_size = load_le<uint32_t>(header_bytes_.data() + header_size);
  const uint64_t data_offset = offset_;
  const uint64_t available = file_size_ - data_offset;
  const bool cut_off = data_size > available;
  const uint64_t record_end = data_offset + data_size;

  try {
    const BagRecordHeader header = BagRecordHeader::parse({header_bytes_.data(), header_size});
    switch (header.op()) {
      case BagOp::kChunk:
        read_chunk(header, record_offset, data_size, std::min<uint64_t>(data_size, available));
        return !finished_;
      case BagOp::kMessageData: {
        if (cut_off) break;
        std::optional<BagMessage> wanted = count_and_filter(header, record_offset);
        if (!wanted) break;
        BagMessage& found = *wanted;
        if (data_size > options_.max_chunk_bytes) {
          warn(at(record_offset) + ": message of " + std::to_string(data_size) +
               " bytes is larger than the limit; skipped");
          break;
        }
        if (!read_bytes(record_, data_size)) return false;
        found.data = {record_.data(), data_size};
        message = found;
        break;
      }
      case BagOp::kConnection: {
        ++stats_.top_level_connections;
        if (cut_off || data_size > options_.max_chunk_bytes) break;
        if (!read_bytes(record_, data_size)) return false;
        read_connection(header, {record_.data(), data_size}, record_offset);
        break;
      }
      case BagOp::kIndexData:
        stats_.index_counts[header.u32("conn")] += header.u32("count");
        break;
      case BagOp::kBagHeader:
        if (!header_.present) {
          header_.index_pos = header.u64("index_pos");
          header_.conn_count = header.u32("conn_count");
          header_.chunk_count = header.u32("chunk_count");
          header_.present = true;
        }
        break;
      case BagOp::kChunkInfo:
        break;
      default:
        warn(at(record_offset) + ": unknown record op " +
             std::to_string(static_cast<int>(header.op())) + "; skipped");
        break;
    }
  } catch (const std::runtime_error& e) {  // BagFormatError, SerializationError
    warn(at(record_offset) + ": " + e.what() + "; record skipped");
  }
  if (cut_off) {
    warn(at(record_offset) + ": the file ends inside this record (" + std::to_string(available) +
         " of " + std::to_string(data_size) + " data bytes there)");
    return false;
  }
  skip_to(record_end);
  return true;
}

void BagRecordReader::read_chunk(const BagRecordHeader& header, uint64_t record_offset,
                                 uint64_t data_size, uint64_t available) {
  const uint64_t chunk_end = offset_ + data_size;
  ++stats_.chunks;
  const std::string name = header.string("compression").substr(0, kMaxCompressionNameBytes);
  const uint32_t declared_size = header.u32("size");
  if (std::find(stats_.compressions.begin(), stats_.compressions.end(), name) ==
      stats_.compressions.end()) {
    stats_.compressions.push_back(name);
  }
  const bool cut_off = available < data_size;
  auto finish_record = [&] {
    if (cut_off) {
      warn(at(record_offset) + ": the file ends inside this chunk (" + std::to_string(available) +
           " of " + std::to_string(data_size) + " bytes there)");
      finished_ = true;
    } else {
      skip_to(chunk_end);
    }
  };
  // Sizes 0 and 0 are also what rosbag writes before a chunk is closed: nothing to read here
  // (an unclosed uncompressed chunk's records follow as if outside a chunk).
  if (!options_.read_chunks || (declared_size == 0 && data_size == 0)) return finish_record();

  const std::optional<ChunkCompression> compression = parse_chunk_compression(name);
  if (!compression) {
    warn(at(record_offset) + ": chunk with unknown compression '" + name + "'; skipped");
    return finish_record();
  }
  if (declared_size > options_.max_chunk_bytes || available > options_.max_chunk_bytes) {
    warn(at(record_offset) + ": chunk of " + std::to_string(declared_size) + " bytes (" +
         std::to_string(data_size) + " stored) is larger than the limit of " +
         std::to_string(options_.max_chunk_bytes) + "; skipped");
    return finish_record();
  }
  if (*compression == ChunkCompression::kNone) {
    if (!read_bytes(chunk_, available)) return;
    chunk_size_ = static_cast<size_t>(available);
    if (!cut_off && data_size != declared_size) {
      warn(at(record_offset) + ": uncompressed chunk holds " + std::to_string(data_size) +
           " bytes but declares " + std::to_string(declared_size) + "; reading what it holds");
    }
  } else {
    if (!read_bytes(record_, available)) return;
    const ChunkDecompression result = decompress_chunk(
        *compression, {record_.data(), static_cast<size_t>(available)}, declared_size, chunk_);
    chunk_size_ = result.size;
    const bool expected_short = cut_off && result.status == ChunkDecompression::Status::kShort;
    if (result.status != ChunkDecompression::Status::kComplete && !expected_short) {
      warn(at(record_offset) + ": " + name + " chunk " + result.problem +
           "; reading the records that came out");
    }
  }
  in_chunk_ = true;
  chunk_cursor_ = 0;
  chunk_offset_ = record_offset;
  finish_record();
}

std::optional<BagMessage> BagRecordReader::next_in_chunk() {
  while (chunk_cursor_ < chunk_size_) {
    const size_t position = chunk_cursor_;
    const size_t left = chunk_size_ - position;
    auto where = [&] { return at(chunk_offset_) + ", chunk byte " + std::to_string(position); };
    if (left < 8) {
      warn(where() + ": " + std::to_string(left) + " stray bytes at the end of the chunk");
      break;
    }
    const uint8_t* record = chunk_.data() + position;
    const uint32_t header_size = load_le<uint32_t>(record);
    if (header_size > left - 8) {
      warn(where() + ": header length " + std::to_string(header_size) +
           " runs past the end of the chunk; the rest of the chunk is skipped");
      break;
    }
    const uint32_t data_size = load_le<uint32_t>(record + 4 + header_size);
    if (data_size > left - 8 - header_size) {
      warn(where() + ": record of " + std::to_string(data_size) +
           " data bytes runs past the end of the chunk; the rest of the chunk is skipped");
      break;
    }
    chunk_cursor_ = position + 8 + header_size + data_size;
    const ByteView data{record + 8 + header_size, data_size};
    try {
      const BagRecordHeader header = BagRecordHeader::parse({record + 4, header_size});
      switch (header.op()) {
        case BagOp::kMessageData: {
          std::optional<BagMessage> wanted = count_and_filter(header, chunk_offset_);
          if (!wanted) break;
          BagMessage& message = *wanted;
          message.data = data;
          return message;
        }
        case BagOp::kConnection:
          read_connection(header, data, chunk_offset_);
          break;
        default:  // only messages and connections belong in chunks; anything else is inert
          break;
      }
    } catch (const std::runtime_error& e) {  // BagFormatError, SerializationError
      warn(where() + ": " + e.what() + "; record skipped");
    }
  }
  in_chunk_ = false;
  return std::nullopt;
}

void BagRecordReader::read_connection(const BagRecordHeader& header, ByteView data,
                                      uint64_t offset) {
  BagConnection connection;
  connection.id = header.u32("conn");
  connection.topic = header.string("topic");
  const BagRecordHeader fields = BagRecordHeader::parse(data);
  connection.type = fields.string("type");
  if (const auto md5 = fields.find("md5sum")) connection.md5sum = md5->as_string_view();
  if (const auto definition = fields.find("message_definition")) {
    connection.message_definition = definition->as_string_view();
  }
  const auto [existing, inserted] = connections_.emplace(connection.id, connection);
  if (!inserted &&
      (existing->second.topic != connection.topic || existing->second.type != connection.type)) {
    warn(at(offset) + ": connection " + std::to_string(connection.id) + " redefined as " +
         connection.topic + " (" + connection.type + "); keeping " + existing->second.topic);
  }
}

bool BagRecordReader::read_bytes(std::vector<uint8_t>& buffer, uint64_t size) {
  if (buffer.size() < size) buffer.resize(static_cast<size_t>(size));
  stream_.read(reinterpret_cast<char*>(buffer.data()), static_cast<std::streamsize>(size));
  const auto got = static_cast<uint64_t>(stream_.gcount());
  offset_ += got;
  if (got != size) {
    warn(at(offset_) + ": read error (" + std::to_string(got) + " of " + std::to_string(size) +
         " bytes); reading stops");
    finished_ = true;
    in_chunk_ = false;
    return false;
  }
  return true;
}

void BagRecordReader::skip_to(uint64_t offset) {
  if (offset == offset_) return;
  stream_.seekg(static_cast<std::streamoff>(offset));
  offset_ = offset;
}

void BagRecordReader::warn(const std::string& message) {
  ++stats_.warnings;
  if (options_.warn) options_.warn(message);
}

std::optional<BagMessage> BagRecordReader::count_and_filter(const BagRecordHeader& header,
                                                            uint64_t offset) {
  BagMessage message;
  message.connection = header.u32("conn");
  message.time_ns = header.time_ns("time");
  message.offset = offset;
  ++stats_.message_counts[message.connection];
  const auto known = connections_.find(message.connection);
  const BagConnection* connection = known == connections_.end() ? nullptr : &known->second;
  if (options_.wanted && !options_.wanted(message, connection)) return std::nullopt;
  return message;
}

std::string BagRecordReader::at(uint64_t offset) const {
  return "record at offset " + std::to_string(offset);
}

}  // namespace featsense::slam
