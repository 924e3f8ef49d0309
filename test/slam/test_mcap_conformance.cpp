// The MCAP record reader against the conformance files of foxglove/mcap: every .mcap must
// give, record by record, what its .json lists (the suite's streamed-reader rule: chunk
// contents in the chunk's place, the Chunk and MessageIndex records themselves left out).

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "mcap/mcap_record_reader.hpp"
#include "mcap/mcap_records.hpp"

namespace featsense::slam {
namespace {

using nlohmann::json;

json text(uint64_t value) { return std::to_string(value); }

json bytes(ByteView view) {
  json out = json::array();
  for (size_t i = 0; i < view.size; ++i) out.push_back(std::to_string(view.data[i]));
  return out;
}

json string_map(const McapStringMap& map) {
  json out = json::object();
  for (const auto& [key, value] : map) out[key] = value;
  return out;
}

json id_map(const std::map<uint16_t, uint64_t>& map) {
  json out = json::object();
  for (const auto& [key, value] : map) out[std::to_string(key)] = text(value);
  return out;
}

/// A record in the suite's form: fields sorted by name, integers as decimal strings.
json fields_of(const McapRecord& record) {
  const ByteView c = record.content;
  switch (record.opcode) {
    case McapOpcode::kHeader: {
      const McapHeader r = parse_mcap_header(c);
      return {{"library", r.library}, {"profile", r.profile}};
    }
    case McapOpcode::kFooter: {
      const McapFooter r = parse_mcap_footer(c);
      return {{"summary_crc", text(r.summary_crc)},
              {"summary_offset_start", text(r.summary_offset_start)},
              {"summary_start", text(r.summary_start)}};
    }
    case McapOpcode::kSchema: {
      const McapSchema r = parse_mcap_schema(c);
      return {
          {"data", bytes(r.data)}, {"encoding", r.encoding}, {"id", text(r.id)}, {"name", r.name}};
    }
    case McapOpcode::kChannel: {
      const McapChannel r = parse_mcap_channel(c);
      return {{"id", text(r.id)},
              {"message_encoding", r.message_encoding},
              {"metadata", string_map(r.metadata)},
              {"schema_id", text(r.schema_id)},
              {"topic", r.topic}};
    }
    case McapOpcode::kMessage: {
      const McapMessage r = parse_mcap_message(c);
      return {{"channel_id", text(r.channel_id)},
              {"data", bytes(r.data)},
              {"log_time", text(r.log_time)},
              {"publish_time", text(r.publish_time)},
              {"sequence", text(r.sequence)}};
    }
    case McapOpcode::kChunkIndex: {
      const McapChunkIndex r = parse_mcap_chunk_index(c);
      return {{"chunk_length", text(r.chunk_length)},
              {"chunk_start_offset", text(r.chunk_start_offset)},
              {"compressed_size", text(r.compressed_size)},
              {"compression", r.compression},
              {"message_end_time", text(r.message_end_time)},
              {"message_index_length", text(r.message_index_length)},
              {"message_index_offsets", id_map(r.message_index_offsets)},
              {"message_start_time", text(r.message_start_time)},
              {"uncompressed_size", text(r.uncompressed_size)}};
    }
    case McapOpcode::kAttachment: {
      const McapAttachment r = parse_mcap_attachment(c);
      return {{"create_time", text(r.create_time)},
              {"data", bytes(r.data)},
              {"log_time", text(r.log_time)},
              {"media_type", r.media_type},
              {"name", r.name}};
    }
    case McapOpcode::kAttachmentIndex: {
      const McapAttachmentIndex r = parse_mcap_attachment_index(c);
      return {{"create_time", text(r.create_time)},
              {"data_size", text(r.data_size)},
              {"length", text(r.length)},
              {"log_time", text(r.log_time)},
              {"media_type", r.media_type},
              {"name", r.name},
              {"offset", text(r.offset)}};
    }
    case McapOpcode::kStatistics: {
      const McapStatistics r = parse_mcap_statistics(c);
      return {{"attachment_count", text(r.attachment_count)},
              {"channel_count", text(r.channel_count)},
              {"channel_message_counts", id_map(r.channel_message_counts)},
              {"chunk_count", text(r.chunk_count)},
              {"message_count", text(r.message_count)},
              {"message_end_time", text(r.message_end_time)},
              {"message_start_time", text(r.message_start_time)},
              {"metadata_count", text(r.metadata_count)},
              {"schema_count", text(r.schema_count)}};
    }
    case McapOpcode::kMetadata: {
      const McapMetadata r = parse_mcap_metadata(c);
      return {{"metadata", string_map(r.metadata)}, {"name", r.name}};
    }
    case McapOpcode::kMetadataIndex: {
      const McapMetadataIndex r = parse_mcap_metadata_index(c);
      return {{"length", text(r.length)}, {"name", r.name}, {"offset", text(r.offset)}};
    }
    case McapOpcode::kSummaryOffset: {
      const McapSummaryOffset r = parse_mcap_summary_offset(c);
      return {{"group_length", text(r.group_length)},
              {"group_opcode", text(r.group_opcode)},
              {"group_start", text(r.group_start)}};
    }
    case McapOpcode::kDataEnd:
      return {{"data_section_crc", text(parse_mcap_data_end(c).data_section_crc)}};
    default:
      return {{"unknown_opcode", text(static_cast<uint64_t>(record.opcode))}};
  }
}

/// The suite writes fields as [[name, value], ...]; this reader's are a name-sorted object.
json suite_fields(const json& pairs) {
  json out = json::object();
  for (const json& pair : pairs) out[pair[0].get<std::string>()] = pair[1];
  return out;
}

std::vector<std::filesystem::path> conformance_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.path().extension() == ".mcap") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(McapConformance, EveryFileGivesTheRecordsItsJsonLists) {
  FEATSENSE_SHARED_FILE(dir, "mcap/conformance");
  const std::vector<std::filesystem::path> files = conformance_files(dir);
  ASSERT_EQ(files.size(), 29u);
  for (const std::filesystem::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    std::ifstream json_file(std::filesystem::path(path).replace_extension(".json"));
    const json expected = json::parse(json_file)["records"];

    std::ifstream stream(path, std::ios::binary);
    std::vector<std::string> warnings;
    McapReadOptions options;
    options.warn = [&warnings](const std::string& message) { warnings.push_back(message); };
    McapRecordReader reader(stream, path.string(), options);
    json got = json::array();
    while (const std::optional<McapRecord> record = reader.next()) {
      if (record->opcode == McapOpcode::kChunk || record->opcode == McapOpcode::kMessageIndex) {
        continue;
      }
      got.push_back({{"type", to_string(record->opcode)}, {"fields", fields_of(*record)}});
    }
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    EXPECT_TRUE(reader.reached_footer());
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i]["type"], expected[i]["type"]) << "record " << i;
      EXPECT_EQ(got[i]["fields"], suite_fields(expected[i]["fields"]))
          << "record " << i << " (" << expected[i]["type"] << ")";
    }
  }
}

}  // namespace
}  // namespace featsense::slam
