// The scan source of any message log (ROS 1 bag, ROS 2 bag, MCAP): topic choice, the decoder
// of the topic's type, streaming.

#include <utility>

#include "imu_sweep_assigner.hpp"
#include "rosbag/bag_imu_topic.hpp"
#include "rosbag/bag_topic_choice.hpp"
#include "rosbag/message_log.hpp"

namespace featsense::slam {
namespace {

class MessageLogSource final : public ScanSource {
 public:
  MessageLogSource(SourceInfo info, std::unique_ptr<MessageLog> log, const BagTopic& topic,
                   std::unique_ptr<BagScanDecoder> decoder, BagImuTopic imu)
      : info_(std::move(info)),
        log_(std::move(log)),
        decoder_(std::move(decoder)),
        imu_decoder_(std::move(imu.decoder)),
        imu_(detail::sweep_duration_ns(info_.sensor.rate_hz)) {
    cursor_ = log_->open(topic, [this](const std::string& message) { warn(message); });
    if (imu.topic != nullptr && imu_decoder_) {
      imu_cursor_ = log_->open(*imu.topic, [this](const std::string& message) { warn(message); });
    }
    report_.warn = [this](const std::string& message) { warn(message); };
    report_.skip_frame = [this](const std::string& message) { skip_frame(message); };
  }

  std::optional<Scan> next() override {
    for (;;) {
      std::optional<Scan> scan = decoder_->take_pending();
      if (scan) return deliver(std::move(*scan));
      if (done_) {
        if (!imu_checked_) {
          imu_checked_ = true;
          const std::string mismatch = detail::clock_mismatch_warning(imu_, info_.path);
          if (!mismatch.empty()) warn(mismatch);
        }
        return std::nullopt;
      }
      if (std::optional<BagMessage> message = cursor_->next()) {
        scan = decoder_->decode(*message, report_);
      } else {
        done_ = true;
        scan = decoder_->finish(report_);
      }
      if (scan) return deliver(std::move(*scan));
    }
  }

  const SourceInfo& info() const override { return info_; }

 private:
  /// Hands a scan out with the IMU's samples of its sweep: the IMU topic is read on, in
  /// recording order, until it has passed the sweep's end.
  Scan deliver(Scan scan) {
    if (imu_cursor_) {
      while (!imu_.covers(scan)) {
        std::optional<BagMessage> message = imu_cursor_->next();
        if (!message) {
          imu_cursor_.reset();
          break;
        }
        if (std::optional<ImuSample> sample = imu_decoder_->decode(*message, report_)) {
          imu_.add(*sample);
        }
      }
      imu_.attach(scan);
    } else if (imu_decoder_) {
      imu_.attach(scan);  // the topic has ended: what is buffered still goes to its sweep
    }
    count_frame();
    return scan;
  }

  SourceInfo info_;
  std::unique_ptr<MessageLog> log_;
  std::unique_ptr<MessageCursor> cursor_;  // reads log_, so it comes after it
  std::unique_ptr<BagScanDecoder> decoder_;
  std::unique_ptr<ImuMessageDecoder> imu_decoder_;
  std::unique_ptr<MessageCursor> imu_cursor_;  // reads log_, so it comes after it
  detail::ImuSweepAssigner imu_;
  DecodeReport report_;
  bool done_ = false;
  bool imu_checked_ = false;
};

std::unique_ptr<BagScanDecoder> make_decoder(const BagTopicContext& context,
                                             const RosbagDependencies& dependencies,
                                             SourceInfo& info) {
  switch (classify_topic(context.topic)) {
    case BagTopicKind::kPointCloud2:
      return make_pointcloud2_decoder(context, dependencies.organize, dependencies.sensor_for,
                                      info);
    case BagTopicKind::kVelodyneScan:
      return dependencies.velodyne_packets(context, info);
    default:
      return dependencies.ouster_packets(context, info);
  }
}

const char* encoding_name(MessageEncoding encoding) {
  return encoding == MessageEncoding::kCdr ? "cdr" : "ros1";
}

}  // namespace

std::vector<std::string> describe_topics(const BagCatalog& catalog) {
  std::vector<std::string> out;
  for (const BagTopic& topic : catalog.topics) {
    out.push_back(topic.name + " (" + topic.type + ", " + encoding_name(topic.encoding) + ", " +
                  std::to_string(topic.messages) + " messages)");
  }
  return out;
}

std::unique_ptr<ScanSource> open_message_log_source(std::unique_ptr<MessageLog> log,
                                                    SourceInfo info, const SourceOptions& options,
                                                    const RosbagDependencies& dependencies) {
  const BagCatalog& catalog = log->catalog();
  const BagTopic& topic = choose_scan_topic(catalog, options.topic, info.path);
  MessageLog& messages = *log;
  const BagTopicContext context{[&messages](const BagTopic& wanted) {
                                  return messages.open(wanted, [](const std::string&) {});
                                },
                                info.path, catalog, topic, options};
  std::unique_ptr<BagScanDecoder> decoder = make_decoder(context, dependencies, info);

  std::string detail = "topic " + topic.name + " (" + topic.type + "), " + log->describe();
  if (!info.detail.empty()) detail += "; " + info.detail;
  info.detail = detail;
  info.topics = describe_topics(catalog);
  BagImuTopic imu = choose_imu_topic(catalog, topic, *decoder, options, info.path);
  info.imu = imu.description;
  return std::make_unique<MessageLogSource>(std::move(info), std::move(log), topic,
                                            std::move(decoder), std::move(imu));
}

}  // namespace featsense::slam
