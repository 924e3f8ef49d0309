#include "mcap/mcap_records.hpp"

#include <cstdio>

namespace featsense::slam {
namespace {

/// A RosDeserializer (same little-endian primitives) whose errors name the record type.
class McapFields {
 public:
  McapFields(ByteView content, const char* record) : in_(content), record_(record) {}

  uint8_t u8(const char* what) {
    return guard([&] { return in_.u8(what); });
  }
  uint16_t u16(const char* what) {
    return guard([&] { return in_.u16(what); });
  }
  uint32_t u32(const char* what) {
    return guard([&] { return in_.u32(what); });
  }
  uint64_t u64(const char* what) {
    return guard([&] { return in_.u64(what); });
  }
  std::string string(const char* what) {
    return guard([&] { return in_.string(what); });
  }
  ByteView bytes(uint64_t count, const char* what) {
    if (count > in_.remaining()) {
      throw McapFormatError(std::string(record_) + " " + what + " claims " + std::to_string(count) +
                            " bytes but only " + std::to_string(in_.remaining()) +
                            " remain in the record");
    }
    return guard([&] { return in_.bytes(static_cast<size_t>(count), what); });
  }
  /// A u32 byte length and the bytes it covers, as a reader of its own.
  McapFields group(const char* what) { return McapFields(bytes(u32(what), what), record_); }
  ByteView rest() {
    return guard([&] { return in_.bytes(in_.remaining(), "rest"); });
  }
  size_t remaining() const { return in_.remaining(); }
  size_t position() const { return in_.position(); }

  McapStringMap string_map(const char* what) {
    McapFields entries = group(what);
    McapStringMap map;
    while (entries.remaining() > 0) {
      std::string key = entries.string(what);
      map[std::move(key)] = entries.string(what);
    }
    return map;
  }
  std::map<uint16_t, uint64_t> id_map(const char* what) {
    McapFields entries = group(what);
    std::map<uint16_t, uint64_t> map;
    while (entries.remaining() > 0) {
      const uint16_t key = entries.u16(what);
      map[key] = entries.u64(what);
    }
    return map;
  }

 private:
  template <typename F>
  auto guard(F&& read) -> decltype(read()) {
    try {
      return read();
    } catch (const SerializationError& e) {
      throw McapFormatError(std::string(record_) + " " + e.what());
    }
  }

  RosDeserializer in_;
  const char* record_;
};

}  // namespace

std::string to_string(McapOpcode opcode) {
  switch (opcode) {
    case McapOpcode::kHeader:
      return "Header";
    case McapOpcode::kFooter:
      return "Footer";
    case McapOpcode::kSchema:
      return "Schema";
    case McapOpcode::kChannel:
      return "Channel";
    case McapOpcode::kMessage:
      return "Message";
    case McapOpcode::kChunk:
      return "Chunk";
    case McapOpcode::kMessageIndex:
      return "MessageIndex";
    case McapOpcode::kChunkIndex:
      return "ChunkIndex";
    case McapOpcode::kAttachment:
      return "Attachment";
    case McapOpcode::kAttachmentIndex:
      return "AttachmentIndex";
    case McapOpcode::kStatistics:
      return "Statistics";
    case McapOpcode::kMetadata:
      return "Metadata";
    case McapOpcode::kMetadataIndex:
      return "MetadataIndex";
    case McapOpcode::kSummaryOffset:
      return "SummaryOffset";
    case McapOpcode::kDataEnd:
      return "DataEnd";
  }
  char name[24];
  std::snprintf(name, sizeof name, "opcode 0x%02X", static_cast<unsigned>(opcode));
  return name;
}

McapHeader parse_mcap_header(ByteView content) {
  McapFields in(content, "Header");
  McapHeader header;
  header.profile = in.string("profile");
  header.library = in.string("library");
  return header;
}

McapFooter parse_mcap_footer(ByteView content) {
  McapFields in(content, "Footer");
  McapFooter footer;
  footer.summary_start = in.u64("summary_start");
  footer.summary_offset_start = in.u64("summary_offset_start");
  footer.summary_crc = in.u32("summary_crc");
  return footer;
}

McapSchema parse_mcap_schema(ByteView content) {
  McapFields in(content, "Schema");
  McapSchema schema;
  schema.id = in.u16("id");
  schema.name = in.string("name");
  schema.encoding = in.string("encoding");
  schema.data = in.bytes(in.u32("data length"), "data");
  return schema;
}

McapChannel parse_mcap_channel(ByteView content) {
  McapFields in(content, "Channel");
  McapChannel channel;
  channel.id = in.u16("id");
  channel.schema_id = in.u16("schema_id");
  channel.topic = in.string("topic");
  channel.message_encoding = in.string("message_encoding");
  channel.metadata = in.string_map("metadata");
  return channel;
}

McapMessage parse_mcap_message(ByteView content) {
  McapFields in(content, "Message");
  McapMessage message;
  message.channel_id = in.u16("channel_id");
  message.sequence = in.u32("sequence");
  message.log_time = in.u64("log_time");
  message.publish_time = in.u64("publish_time");
  message.data = in.rest();  // a message has no length field: its data runs to the end
  return message;
}

McapChunk parse_mcap_chunk(ByteView content) {
  McapFields in(content, "Chunk");
  McapChunk chunk;
  chunk.message_start_time = in.u64("message_start_time");
  chunk.message_end_time = in.u64("message_end_time");
  chunk.uncompressed_size = in.u64("uncompressed_size");
  chunk.uncompressed_crc = in.u32("uncompressed_crc");
  chunk.compression = in.string("compression");
  chunk.records = in.bytes(in.u64("records length"), "records");
  return chunk;
}

McapMessageIndex parse_mcap_message_index(ByteView content) {
  McapFields in(content, "MessageIndex");
  McapMessageIndex index;
  index.channel_id = in.u16("channel_id");
  McapFields entries = in.group("records");
  while (entries.remaining() > 0) {
    const uint64_t log_time = entries.u64("records log_time");
    index.records.emplace_back(log_time, entries.u64("records offset"));
  }
  return index;
}

McapChunkIndex parse_mcap_chunk_index(ByteView content) {
  McapFields in(content, "ChunkIndex");
  McapChunkIndex index;
  index.message_start_time = in.u64("message_start_time");
  index.message_end_time = in.u64("message_end_time");
  index.chunk_start_offset = in.u64("chunk_start_offset");
  index.chunk_length = in.u64("chunk_length");
  index.message_index_offsets = in.id_map("message_index_offsets");
  index.message_index_length = in.u64("message_index_length");
  index.compression = in.string("compression");
  index.compressed_size = in.u64("compressed_size");
  index.uncompressed_size = in.u64("uncompressed_size");
  return index;
}

McapAttachment parse_mcap_attachment(ByteView content) {
  McapFields in(content, "Attachment");
  McapAttachment attachment;
  attachment.log_time = in.u64("log_time");
  attachment.create_time = in.u64("create_time");
  attachment.name = in.string("name");
  attachment.media_type = in.string("media_type");
  attachment.data = in.bytes(in.u64("data length"), "data");
  attachment.crc_covered = ByteView{content.data, in.position()};
  attachment.crc = in.u32("crc");
  return attachment;
}

McapAttachmentIndex parse_mcap_attachment_index(ByteView content) {
  McapFields in(content, "AttachmentIndex");
  McapAttachmentIndex index;
  index.offset = in.u64("offset");
  index.length = in.u64("length");
  index.log_time = in.u64("log_time");
  index.create_time = in.u64("create_time");
  index.data_size = in.u64("data_size");
  index.name = in.string("name");
  index.media_type = in.string("media_type");
  return index;
}

McapStatistics parse_mcap_statistics(ByteView content) {
  McapFields in(content, "Statistics");
  McapStatistics statistics;
  statistics.message_count = in.u64("message_count");
  statistics.schema_count = in.u16("schema_count");
  statistics.channel_count = in.u32("channel_count");
  statistics.attachment_count = in.u32("attachment_count");
  statistics.metadata_count = in.u32("metadata_count");
  statistics.chunk_count = in.u32("chunk_count");
  statistics.message_start_time = in.u64("message_start_time");
  statistics.message_end_time = in.u64("message_end_time");
  statistics.channel_message_counts = in.id_map("channel_message_counts");
  return statistics;
}

McapMetadata parse_mcap_metadata(ByteView content) {
  McapFields in(content, "Metadata");
  McapMetadata metadata;
  metadata.name = in.string("name");
  metadata.metadata = in.string_map("metadata");
  return metadata;
}

McapMetadataIndex parse_mcap_metadata_index(ByteView content) {
  McapFields in(content, "MetadataIndex");
  McapMetadataIndex index;
  index.offset = in.u64("offset");
  index.length = in.u64("length");
  index.name = in.string("name");
  return index;
}

McapSummaryOffset parse_mcap_summary_offset(ByteView content) {
  McapFields in(content, "SummaryOffset");
  McapSummaryOffset offset;
  offset.group_opcode = in.u8("group_opcode");
  offset.group_start = in.u64("group_start");
  offset.group_length = in.u64("group_length");
  return offset;
}

McapDataEnd parse_mcap_data_end(ByteView content) {
  McapFields in(content, "DataEnd");
  McapDataEnd data_end;
  data_end.data_section_crc = in.u32("data_section_crc");
  return data_end;
}

}  // namespace featsense::slam
