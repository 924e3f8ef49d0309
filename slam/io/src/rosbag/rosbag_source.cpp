#include "rosbag/rosbag_source.hpp"

#include <fstream>
#include <utility>

#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_record_reader.hpp"

namespace featsense::slam {
namespace {

/// The messages of one topic (by name: a topic may have several connections), read with a
/// record reader of its own over a stream of its own.
class RosbagTopicCursor final : public MessageCursor {
 public:
  RosbagTopicCursor(const std::string& path, const BagCatalog& catalog, std::string topic,
                    WarningSink warn)
      : topic_(std::move(topic)),
        stream_(path, std::ios::binary),
        reader_(stream_, path, read_options(std::move(warn))) {
    for (const auto& [id, connection] : catalog.connections) reader_.add_connection(connection);
  }

  std::optional<BagMessage> next() override { return reader_.next(); }

 private:
  BagReadOptions read_options(WarningSink warn) {
    BagReadOptions options;
    options.wanted = [this](const BagMessage&, const BagConnection* connection) {
      return connection != nullptr && connection->topic == topic_;
    };
    options.warn = std::move(warn);
    return options;
  }

  std::string topic_;
  std::ifstream stream_;
  BagRecordReader reader_;  // reads stream_, so it comes after it
};

class RosbagLog final : public MessageLog {
 public:
  RosbagLog(std::string path, BagCatalog catalog)
      : path_(std::move(path)), catalog_(std::move(catalog)) {}

  const BagCatalog& catalog() const override { return catalog_; }

  std::unique_ptr<MessageCursor> open(const BagTopic& topic, WarningSink warn) override {
    return std::make_unique<RosbagTopicCursor>(path_, catalog_, topic.name, std::move(warn));
  }

  std::string describe() const override {
    std::string compressions;
    for (const std::string& name : catalog_.compressions) {
      compressions += (compressions.empty() ? "" : "+") + name;
    }
    std::string text = std::to_string(catalog_.connections.size()) + " connections, " +
                       (compressions.empty() ? std::string("no chunks") : compressions);
    if (!catalog_.from_index) text += ", no usable index (chunks walked)";
    return text;
  }

 private:
  std::string path_;
  BagCatalog catalog_;
};

}  // namespace

std::unique_ptr<ScanSource> open_rosbag_source(const std::string& path,
                                               const SourceOptions& options,
                                               const RosbagDependencies& dependencies) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(path + ": cannot open");
  BagCatalog catalog = catalog_bag(stream, path);
  SourceInfo info;
  info.format = "rosbag";
  info.path = path;
  return open_message_log_source(std::make_unique<RosbagLog>(path, std::move(catalog)),
                                 std::move(info), options, dependencies);
}

}  // namespace featsense::slam
