#include "mcap/mcap_message_log.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <utility>

#include "mcap/mcap_record_reader.hpp"
#include "rosbag/bag_topic_choice.hpp"

namespace featsense::slam {
namespace {

/// Footer record (opcode, length, 20 bytes of fields) + closing magic.
constexpr uint64_t kFooterRecordBytes = 1 + 8 + 20;

/// What the catalog keeps of the schemas and channels.
struct McapLayout {
  std::map<uint16_t, McapSchema> schemas;  ///< names and encodings only (no data)
  std::map<uint16_t, McapChannel> channels;
  std::map<uint16_t, uint64_t> counts;  ///< messages per channel
  std::vector<std::string> compressions;
  uint64_t chunks = 0;
};

void keep(McapLayout& layout, const McapRecord& record) {
  switch (record.opcode) {
    case McapOpcode::kSchema: {
      McapSchema schema = parse_mcap_schema(record.content);
      schema.data = {};
      layout.schemas.emplace(schema.id, std::move(schema));
      break;
    }
    case McapOpcode::kChannel: {
      McapChannel channel = parse_mcap_channel(record.content);
      layout.channels.emplace(channel.id, std::move(channel));
      break;
    }
    case McapOpcode::kMessage:
      ++layout.counts[parse_mcap_message(record.content).channel_id];
      break;
    case McapOpcode::kChunk: {
      ++layout.chunks;
      const std::string name = parse_mcap_chunk(record.content).compression;
      const std::string shown = name.empty() ? "uncompressed" : name.substr(0, 16);
      if (std::find(layout.compressions.begin(), layout.compressions.end(), shown) ==
          layout.compressions.end()) {
        layout.compressions.push_back(shown);
      }
      break;
    }
    case McapOpcode::kChunkIndex: {
      const std::string name = parse_mcap_chunk_index(record.content).compression;
      const std::string shown = name.empty() ? "uncompressed" : name.substr(0, 16);
      if (std::find(layout.compressions.begin(), layout.compressions.end(), shown) ==
          layout.compressions.end()) {
        layout.compressions.push_back(shown);
      }
      break;
    }
    case McapOpcode::kStatistics: {
      const McapStatistics statistics = parse_mcap_statistics(record.content);
      layout.counts = statistics.channel_message_counts;
      layout.chunks = statistics.chunk_count;
      break;
    }
    default:
      break;
  }
}

/// The layout from the summary section, or nullopt where the file has none that lists the
/// channels and counts them (then the file is scanned).
std::optional<McapLayout> layout_from_summary(std::istream& stream, const std::string& path) {
  McapReadOptions options;
  options.expand_chunks = false;
  McapRecordReader reader(stream, path, options);
  if (reader.file_size() < 2 * sizeof kMcapMagic + kFooterRecordBytes) return std::nullopt;
  const uint64_t footer_at = reader.file_size() - sizeof kMcapMagic - kFooterRecordBytes;
  reader.jump_to(footer_at);
  const std::optional<McapRecord> footer_record = reader.next();
  if (!footer_record || footer_record->opcode != McapOpcode::kFooter) return std::nullopt;
  const McapFooter footer = parse_mcap_footer(footer_record->content);
  if (footer.summary_start == 0 || footer.summary_start >= footer_at) return std::nullopt;
  reader.jump_to(footer.summary_start);
  McapLayout layout;
  bool statistics = false;
  while (const std::optional<McapRecord> record = reader.next()) {
    if (record->opcode == McapOpcode::kFooter) break;
    statistics |= record->opcode == McapOpcode::kStatistics;
    keep(layout, *record);
  }
  if (reader.warnings() > 0 || !statistics) return std::nullopt;
  if (layout.channels.empty() && !layout.counts.empty()) return std::nullopt;
  return layout;
}

/// The messages of a set of channels, in file order.
class McapCursor final : public MessageCursor {
 public:
  McapCursor(const std::string& path, std::set<uint16_t> channels, WarningSink warn)
      : channels_(std::move(channels)),
        stream_(path, std::ios::binary),
        reader_(stream_, path, options(std::move(warn))) {}

  std::optional<BagMessage> next() override {
    while (const std::optional<McapRecord> record = reader_.next()) {
      if (record->opcode != McapOpcode::kMessage) continue;
      McapMessage message;
      try {
        message = parse_mcap_message(record->content);
      } catch (const McapFormatError& e) {
        if (warn_) warn_(std::string(e.what()) + " at offset " + std::to_string(record->offset));
        continue;
      }
      if (channels_.count(message.channel_id) == 0) continue;
      BagMessage out;
      out.connection = message.channel_id;
      out.time_ns = static_cast<int64_t>(message.log_time);
      out.data = message.data;
      out.offset = record->offset;
      return out;
    }
    return std::nullopt;
  }

 private:
  McapReadOptions options(WarningSink warn) {
    warn_ = warn;
    McapReadOptions read;
    read.warn = std::move(warn);
    return read;
  }

  std::set<uint16_t> channels_;
  WarningSink warn_;
  std::ifstream stream_;
  McapRecordReader reader_;  // reads stream_, so it comes after it
};

class McapMessageLog final : public MessageLog {
 public:
  explicit McapMessageLog(std::string path) : path_(std::move(path)) {
    std::ifstream stream(path_, std::ios::binary);
    if (!stream) throw InputError(path_ + ": cannot open");
    std::optional<McapLayout> layout;
    try {
      layout = layout_from_summary(stream, path_);
    } catch (const McapFormatError&) {
      layout.reset();  // a damaged summary: scan instead
    }
    from_summary_ = layout.has_value();
    if (!layout) layout = scan(stream);
    build_catalog(*layout);
  }

  const BagCatalog& catalog() const override { return catalog_; }

  std::unique_ptr<MessageCursor> open(const BagTopic& topic, WarningSink warn) override {
    const auto channels = channels_.find(topic.name);
    return std::make_unique<McapCursor>(
        path_, channels == channels_.end() ? std::set<uint16_t>() : channels->second,
        std::move(warn));
  }

  std::string describe() const override {
    std::string compressions;
    for (const std::string& name : catalog_.compressions) {
      compressions += (compressions.empty() ? "" : "+") + name;
    }
    return std::to_string(catalog_.chunks) + " chunks" +
           (compressions.empty() ? "" : " (" + compressions + ")") +
           (from_summary_ ? ", topics from the summary" : ", no usable summary (file scanned)");
  }

 private:
  McapLayout scan(std::istream& stream) {
    McapReadOptions options;
    options.warn = [this](const std::string& message) { catalog_.warnings.push_back(message); };
    McapRecordReader reader(stream, path_, options);
    McapLayout layout;
    while (const std::optional<McapRecord> record = reader.next()) {
      if (record->opcode == McapOpcode::kStatistics) continue;  // counted here instead
      try {
        keep(layout, *record);
      } catch (const McapFormatError& e) {
        catalog_.warnings.push_back(path_ + " at offset " + std::to_string(record->offset) + ": " +
                                    e.what());
      }
    }
    return layout;
  }

  void build_catalog(const McapLayout& layout) {
    std::map<std::string, BagTopic> topics;
    for (const auto& [id, channel] : layout.channels) {
      BagTopic& topic = topics[channel.topic];
      if (topic.name.empty()) {
        topic.name = channel.topic;
        const auto schema = layout.schemas.find(channel.schema_id);
        topic.type = schema == layout.schemas.end() ? std::string("(no schema)")
                                                    : ros1_style_type(schema->second.name);
        if (channel.message_encoding == "cdr") {
          topic.encoding = MessageEncoding::kCdr;
        } else if (channel.message_encoding != "ros1") {
          // Not a ROS message: shown with its encoding, never decoded as a scan.
          topic.type += " (" + channel.message_encoding + " encoding)";
        }
      }
      const auto count = layout.counts.find(id);
      if (count != layout.counts.end()) topic.messages += count->second;
      channels_[channel.topic].insert(id);
    }
    for (auto& [name, topic] : topics) catalog_.topics.push_back(std::move(topic));
    catalog_.compressions = layout.compressions;
    catalog_.chunks = layout.chunks;
    catalog_.from_index = from_summary_;
  }

  std::string path_;
  bool from_summary_ = false;
  BagCatalog catalog_;
  std::map<std::string, std::set<uint16_t>> channels_;
};

}  // namespace

std::unique_ptr<MessageLog> open_mcap_file(const std::string& path) {
  return std::make_unique<McapMessageLog>(path);
}

}  // namespace featsense::slam
