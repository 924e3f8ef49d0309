#pragma once
/// Decodes a sensor_msgs/PointCloud2 topic into scans: organized clouds (height > 1) map
/// onto the scan directly, unorganized ones go through an organizer (organize.hpp).

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/config.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/point_cloud.hpp"
#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_scan_decoder.hpp"

namespace featsense::slam {

/// Places an unorganized cloud into the scan layout of a sensor (organize() in production).
using CloudOrganizer =
    std::function<Scan(const PointCloud& cloud, const config::SensorModel& sensor)>;

class PointCloud2Decoder final : public BagScanDecoder {
 public:
  /// `sensor` is the model unorganized clouds are organized for. Clouds without a time
  /// field get per-point times from the azimuth when `times_from_azimuth`
  /// (sensor.times_from_azimuth), counted from the message's stamp, the sweep's start.
  /// `encoding`: ROS 1 messages or ROS 2's CDR.
  PointCloud2Decoder(config::SensorModel sensor, CloudOrganizer organize,
                     bool times_from_azimuth = config::SensorConfig{}.times_from_azimuth,
                     MessageEncoding encoding = MessageEncoding::kRos1);

  /// Scan rows: row 0 the highest beam. An organized cloud stored lowest beam first is
  /// flipped; which way the topic's clouds run is decided on the first cloud that tells it,
  /// then kept, so all scans of a topic have one orientation. Scan.sequence is the index of
  /// the message on the topic (skipped messages leave gaps).
  std::optional<Scan> decode(const BagMessage& message, const DecodeReport& report) override;

 private:
  config::SensorModel sensor_;
  CloudOrganizer organize_;
  bool times_from_azimuth_;
  MessageEncoding encoding_;
  std::optional<bool> lowest_first_;
  uint64_t message_index_ = 0;
};

/// Reads the first readable cloud of the topic to choose the sensor model (sensor.preset
/// where set; else a preset by the beam count; else, for organized clouds, one estimated
/// from that cloud), fills info.sensor, info.fields, info.frames, info.detail and info.times, and
/// returns the decoder. Throws InputError where no message of the topic is readable or no
/// sensor model fits.
std::unique_ptr<BagScanDecoder> make_pointcloud2_decoder(const BagTopicContext& context,
                                                         CloudOrganizer organize,
                                                         const SensorLookup& sensor_for,
                                                         SourceInfo& info);

}  // namespace featsense::slam
