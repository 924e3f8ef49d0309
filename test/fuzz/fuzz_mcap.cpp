// Fuzzes the MCAP container: the streaming record reader (chunks decompressed: none, zstd,
// lz4; CRCs checked), every record parser, and the message log (summary or scan, topic
// cursors), over arbitrary bytes. Anything but InputError escaping, a sanitizer report, or a
// hang is a bug.

#include <unistd.h>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "featsense/slam/scan_source.hpp"
#include "mcap/mcap_message_log.hpp"
#include "mcap/mcap_record_reader.hpp"
#include "mcap/mcap_records.hpp"

namespace {

using namespace featsense::slam;

/// Smaller than the reader's 1 GiB so that a lying size costs milliseconds.
constexpr uint64_t kFuzzMaxRecordBytes = uint64_t{16} << 20;

void parse_record(const McapRecord& record) {
  try {
    switch (record.opcode) {
      case McapOpcode::kHeader:
        parse_mcap_header(record.content);
        break;
      case McapOpcode::kFooter:
        parse_mcap_footer(record.content);
        break;
      case McapOpcode::kSchema:
        parse_mcap_schema(record.content);
        break;
      case McapOpcode::kChannel:
        parse_mcap_channel(record.content);
        break;
      case McapOpcode::kMessage:
        parse_mcap_message(record.content);
        break;
      case McapOpcode::kChunk:
        parse_mcap_chunk(record.content);
        break;
      case McapOpcode::kMessageIndex:
        parse_mcap_message_index(record.content);
        break;
      case McapOpcode::kChunkIndex:
        parse_mcap_chunk_index(record.content);
        break;
      case McapOpcode::kAttachment:
        parse_mcap_attachment(record.content);
        break;
      case McapOpcode::kAttachmentIndex:
        parse_mcap_attachment_index(record.content);
        break;
      case McapOpcode::kStatistics:
        parse_mcap_statistics(record.content);
        break;
      case McapOpcode::kMetadata:
        parse_mcap_metadata(record.content);
        break;
      case McapOpcode::kMetadataIndex:
        parse_mcap_metadata_index(record.content);
        break;
      case McapOpcode::kSummaryOffset:
        parse_mcap_summary_offset(record.content);
        break;
      case McapOpcode::kDataEnd:
        parse_mcap_data_end(record.content);
        break;
    }
  } catch (const McapFormatError&) {
  }
}

/// The message log reads files by name: the input goes to a file of this process's own.
std::string scratch_file(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/fuzz_mcap_" + std::to_string(::getpid()) + ".mcap";
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    std::istringstream stream(std::string(reinterpret_cast<const char*>(data), size));
    McapReadOptions options;
    options.max_record_bytes = kFuzzMaxRecordBytes;
    options.warn = [](const std::string&) {};
    McapRecordReader reader(stream, "fuzz.mcap", options);
    while (const std::optional<McapRecord> record = reader.next()) parse_record(*record);
  } catch (const InputError&) {
    return 0;  // not an MCAP file at all: the expected answer to most inputs
  }
  try {
    std::unique_ptr<MessageLog> log = open_mcap_file(scratch_file(data, size));
    for (const BagTopic& topic : log->catalog().topics) {
      std::unique_ptr<MessageCursor> cursor = log->open(topic, [](const std::string&) {});
      while (cursor->next()) {
      }
    }
  } catch (const InputError&) {
  }
  return 0;
}
