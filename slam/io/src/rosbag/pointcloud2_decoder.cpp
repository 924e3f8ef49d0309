#include "rosbag/pointcloud2_decoder.hpp"

#include <utility>

#include "cloud/cloud_file_io.hpp"
#include "cloud/sensor_guess.hpp"
#include "featsense/slam/io/azimuth_times.hpp"
#include "featsense/slam/io/organize.hpp"
#include "ros2/cdr_pointcloud2.hpp"
#include "rosbag/cloud_sensor_model.hpp"
#include "rosbag/pointcloud2.hpp"
#include "rosbag/pointcloud2_convert.hpp"

namespace featsense::slam {
namespace {

std::string describe_message(uint64_t index, const BagMessage& message) {
  return "message " + std::to_string(index) + " (record at offset " +
         std::to_string(message.offset) + ")";
}

/// A PointCloud2 message of either encoding.
PointCloud2View parse_cloud(ByteView data, MessageEncoding encoding) {
  return encoding == MessageEncoding::kCdr ? parse_pointcloud2_cdr(data) : parse_pointcloud2(data);
}

/// Per-point times from the azimuth (azimuth_times.hpp) of a cloud's points in the order
/// the message stores them; a message's stamp is its sweep's start.
AzimuthTimes times_from_azimuth(const std::vector<Eigen::Vector3f>& xyz,
                                const config::SensorModel& sensor) {
  return azimuth_times(xyz, sensor.rate_hz, SweepReference::kSweepStart);
}

/// What the first readable cloud of a topic tells about all of them.
struct FirstCloud {
  uint32_t height = 0;
  uint32_t width = 0;
  std::vector<std::string> fields;
  std::string time_field;  ///< empty where the clouds have none
  int rings = 0;
  std::optional<Scan> organized;     ///< row 0 the highest beam
  std::vector<Eigen::Vector3f> xyz;  ///< the points in the order the message stores them
  /// An unorganized cloud's points as the organizer gets them (rings included), for the check
  /// that they fit the sensor.
  PointCloud points;
};

FirstCloud read_first_cloud(const BagTopicContext& context) {
  std::string first_problem;
  std::unique_ptr<MessageCursor> messages = context.open_topic(context.topic);
  const MessageEncoding encoding = context.topic.encoding;
  uint64_t index = 0;
  while (const std::optional<BagMessage> message = messages->next()) {
    std::string problem;
    try {
      const PointCloud2View cloud = parse_cloud(message->data, encoding);
      problem = layout_problem(cloud);
      if (problem.empty()) {
        FirstCloud first;
        first.height = cloud.height;
        first.width = cloud.width;
        for (const PointFieldDesc& field : cloud.fields) first.fields.push_back(field.name);
        if (const PointFieldDesc* time = time_field(cloud)) first.time_field = time->name;
        first.rings = ring_count(cloud);
        if (cloud.height > 1) {
          first.organized = organized_cloud_to_scan(cloud, message->time_ns);
          first.xyz = first.organized->xyz;
          if (rows_lowest_first(*first.organized).value_or(false)) flip_rows(*first.organized);
        } else {
          first.points = cloud_to_points(cloud, message->time_ns);
          first.xyz = first.points.xyz;
        }
        return first;
      }
    } catch (const SerializationError& e) {
      problem = std::string("PointCloud2 ") + e.what();
    }
    if (first_problem.empty()) first_problem = describe_message(index, *message) + ": " + problem;
    ++index;
  }
  std::string message =
      context.origin + ": no readable PointCloud2 message on " + context.topic.name;
  if (!first_problem.empty()) message += " (first problem: " + first_problem + ")";
  throw InputError(message);
}

config::SensorModel choose_sensor(const BagTopicContext& context, const FirstCloud& first,
                                  const SensorLookup& sensor_for, std::string& how) {
  const SourceOptions& options = context.options;
  if (options.sensor_preset != "auto") {
    how = "sensor.preset " + options.sensor_preset;
    return sensor_for(options, options.sensor_preset);
  }
  if (first.organized) {
    if (const auto preset = preset_for_rings(static_cast<int>(first.height), false)) {
      how = "preset " + *preset + " by its " + std::to_string(first.height) + " rows";
      return sensor_for(options, *preset);
    }
    if (auto estimated = sensor_model_from_scan(*first.organized)) {
      how = "sensor estimated from the first cloud's rows (no preset has " +
            std::to_string(first.height) + " beams)";
      return *estimated;
    }
    throw InputError(context.origin + ": the clouds on " + context.topic.name + " have " +
                     std::to_string(first.height) +
                     " rows, which no preset has, and too few returns to estimate the beams; "
                     "set sensor.preset");
  }
  if (first.rings == 0) {
    // Told by the elevations the points lie on, as clouds in files are (cloud_to_scan.cpp).
    PointCloud points;
    points.xyz = first.xyz;
    if (const std::optional<cloud::SensorFromPoints> found = cloud::sensor_from_points(points)) {
      how = found->why;
      return found->preset ? sensor_for(options, *found->preset) : *found->measured;
    }
    throw InputError(context.origin + ": the clouds on " + context.topic.name +
                     " are unorganized, have no ring field and lie on no preset's beams; set "
                     "sensor.preset to the sensor that recorded them");
  }
  if (const auto preset = preset_for_rings(first.rings, true)) {
    how = "preset " + *preset + " by its " + std::to_string(first.rings) + " rings";
    return sensor_for(options, *preset);
  }
  throw InputError(context.origin + ": the clouds on " + context.topic.name + " have " +
                   std::to_string(first.rings) + " rings, more than any preset; set sensor.preset");
}

}  // namespace

PointCloud2Decoder::PointCloud2Decoder(config::SensorModel sensor, CloudOrganizer organize,
                                       bool times_from_azimuth, MessageEncoding encoding)
    : sensor_(std::move(sensor)),
      organize_(std::move(organize)),
      times_from_azimuth_(times_from_azimuth),
      encoding_(encoding) {}

std::optional<Scan> PointCloud2Decoder::decode(const BagMessage& message,
                                               const DecodeReport& report) {
  const uint64_t index = message_index_++;
  PointCloud2View cloud;
  try {
    cloud = parse_cloud(message.data, encoding_);
  } catch (const SerializationError& e) {
    report.skip_frame(describe_message(index, message) + ": PointCloud2 " + e.what());
    return std::nullopt;
  }
  if (const std::string problem = layout_problem(cloud); !problem.empty()) {
    report.skip_frame(describe_message(index, message) + ": " + problem);
    return std::nullopt;
  }
  const bool derive_times = times_from_azimuth_ && time_field(cloud) == nullptr;
  // Where the points' order tells no times they stay 0, with a warning.
  auto derived = [&](const std::vector<Eigen::Vector3f>& xyz) {
    AzimuthTimes times = times_from_azimuth(xyz, sensor_);
    if (!times.found()) {
      report.warn(describe_message(index, message) +
                  ": no per-point times from the azimuth: " + times.problem);
    }
    return std::move(times.offset_s);
  };
  Scan scan;
  if (cloud.height > 1) {
    scan = organized_cloud_to_scan(cloud, message.time_ns);
    if (derive_times) {
      if (std::vector<float> times = derived(scan.xyz); !times.empty()) {
        scan.time_offset_s = std::move(times);
      }
    }
    if (!lowest_first_) lowest_first_ = rows_lowest_first(scan);
    if (lowest_first_.value_or(false)) flip_rows(scan);
  } else {
    PointCloud points = cloud_to_points(cloud, message.time_ns);
    if (derive_times) points.time_offset_s = derived(points.xyz);
    scan = organize_(points, sensor_);
  }
  scan.sequence = index;
  return scan;
}

std::unique_ptr<BagScanDecoder> make_pointcloud2_decoder(const BagTopicContext& context,
                                                         CloudOrganizer organize,
                                                         const SensorLookup& sensor_for,
                                                         SourceInfo& info) {
  const FirstCloud first = read_first_cloud(context);
  std::string how;
  config::SensorModel sensor = choose_sensor(context, first, sensor_for, how);
  if (first.organized) sensor.columns = static_cast<int>(first.width);
  // Unorganized clouds are placed by their rings or their points' elevations: a model most of
  // them fall outside of would map what is left of every scan. As for clouds in files, that
  // is an error naming the share lost and the presets whose beams the points lie on.
  if (!first.organized) {
    OrganizeStats stats;
    // The parameter `organize` is the per-scan organizer; the check uses the library's.
    slam::organize(first.points, sensor, &stats);
    cloud::check_sensor_fits(stats, first.points, sensor,
                             context.origin + ", topic " + context.topic.name);
  }
  info.sensor = sensor;
  info.sensor_from_metadata = false;
  info.fields = first.fields;
  info.frames = static_cast<size_t>(context.topic.messages);
  info.detail = (first.organized ? "organized " : "unorganized ") + std::to_string(first.height) +
                " x " + std::to_string(first.width) + ", " + how;
  const bool from_azimuth = context.options.times_from_azimuth;
  if (first.time_field.empty() && from_azimuth) {
    const AzimuthTimes derived = times_from_azimuth(first.xyz, sensor);
    info.times = describe_times("", &derived);
  } else {
    info.times = describe_times(first.time_field, nullptr);
  }
  return std::make_unique<PointCloud2Decoder>(std::move(sensor), std::move(organize), from_azimuth,
                                              context.topic.encoding);
}

}  // namespace featsense::slam
