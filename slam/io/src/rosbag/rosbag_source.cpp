#include "rosbag/rosbag_source.hpp"

#include <fstream>
#include <utility>

#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_record_reader.hpp"
#include "rosbag/bag_topic_choice.hpp"

namespace featsense::slam {
namespace {

class RosbagSource final : public ScanSource {
 public:
  RosbagSource(SourceInfo info, const BagCatalog& catalog, const BagTopic& topic,
               std::unique_ptr<BagScanDecoder> decoder)
      : info_(std::move(info)),
        topic_(topic.name),
        stream_(info_.path, std::ios::binary),
        reader_(stream_, info_.path, read_options()),
        decoder_(std::move(decoder)) {
    for (const auto& [id, connection] : catalog.connections) reader_.add_connection(connection);
    report_.warn = [this](const std::string& message) { warn(message); };
    report_.skip_frame = [this](const std::string& message) { skip_frame(message); };
  }

  std::optional<Scan> next() override {
    while (!done_) {
      std::optional<Scan> scan;
      if (std::optional<BagMessage> message = reader_.next()) {
        scan = decoder_->decode(*message, report_);
      } else {
        done_ = true;
        scan = decoder_->finish(report_);
      }
      if (scan) {
        count_frame();
        return scan;
      }
    }
    return std::nullopt;
  }

  const SourceInfo& info() const override { return info_; }

 private:
  /// Messages of the chosen topic only (by name: a topic may have several connections);
  /// damage the reader meets becomes a counted warning of this source.
  BagReadOptions read_options() {
    BagReadOptions options;
    options.wanted = [this](const BagMessage&, const BagConnection* connection) {
      return connection != nullptr && connection->topic == topic_;
    };
    options.warn = [this](const std::string& message) { warn(message); };
    return options;
  }

  SourceInfo info_;
  std::string topic_;
  std::ifstream stream_;
  BagRecordReader reader_;  // reads stream_, so it comes after it
  std::unique_ptr<BagScanDecoder> decoder_;
  DecodeReport report_;
  bool done_ = false;
};

std::string join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (const std::string& part : parts) out += (out.empty() ? "" : separator) + part;
  return out;
}

}  // namespace

std::unique_ptr<ScanSource> open_rosbag_source(const std::string& path,
                                               const SourceOptions& options,
                                               const RosbagDependencies& dependencies) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(path + ": cannot open");
  const BagCatalog catalog = catalog_bag(stream, path);
  const BagTopic& topic = choose_scan_topic(catalog, options.topic, path);

  SourceInfo info;
  info.format = "rosbag";
  info.path = path;
  const BagTopicContext context{stream, path, catalog, topic, options};
  std::unique_ptr<BagScanDecoder> decoder;
  if (classify_topic(topic) == BagTopicKind::kPointCloud2) {
    decoder =
        make_pointcloud2_decoder(context, dependencies.organize, dependencies.sensor_for, info);
  } else {
    decoder = dependencies.ouster_packets(context, info);
  }

  std::string detail =
      "topic " + topic.name + " (" + topic.type + "), " +
      std::to_string(catalog.connections.size()) + " connections, " +
      (catalog.compressions.empty() ? std::string("no chunks") : join(catalog.compressions, "+"));
  if (!catalog.from_index) detail += ", no usable index (chunks walked)";
  if (!info.detail.empty()) detail += "; " + info.detail;
  info.detail = detail;
  return std::make_unique<RosbagSource>(std::move(info), catalog, topic, std::move(decoder));
}

}  // namespace featsense::slam
