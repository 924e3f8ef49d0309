// Format detection and the range limits every source gets.

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "featsense/slam/io/readers.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

/// Drops returns outside [min, max] metres, inside the self box and any non-finite point,
/// whatever the reader.
class RangeLimitedSource final : public ScanSource {
 public:
  RangeLimitedSource(std::unique_ptr<ScanSource> inner, double min_m, double max_m,
                     const std::optional<std::array<double, 6>>& self_box)
      : inner_(std::move(inner)), min_m_(min_m), max_m_(max_m) {
    if (self_box) {
      const std::array<double, 6>& b = *self_box;
      box_min_ = Eigen::Vector3f(static_cast<float>(b[0]), static_cast<float>(b[1]),
                                 static_cast<float>(b[2]));
      box_max_ = Eigen::Vector3f(static_cast<float>(b[3]), static_cast<float>(b[4]),
                                 static_cast<float>(b[5]));
      has_box_ = true;
    }
  }

  std::optional<Scan> next() override {
    std::optional<Scan> scan = inner_->next();
    if (!scan) return scan;
    for (size_t i = 0; i < scan->size(); ++i) {
      if (!scan->valid[i]) continue;
      const Eigen::Vector3f& p = scan->xyz[i];
      const float r = p.norm();
      if (!std::isfinite(r) || r < min_m_ || r > max_m_ || r == 0.0f ||
          (has_box_ && (p.array() >= box_min_.array()).all() &&
           (p.array() <= box_max_.array()).all())) {
        scan->invalidate(i);
      }
    }
    return scan;
  }
  const SourceInfo& info() const override { return inner_->info(); }
  const ReadStats& stats() const override { return inner_->stats(); }

 private:
  std::unique_ptr<ScanSource> inner_;
  float min_m_;
  float max_m_;
  bool has_box_ = false;
  Eigen::Vector3f box_min_ = Eigen::Vector3f::Zero();
  Eigen::Vector3f box_max_ = Eigen::Vector3f::Zero();
};

bool starts_with(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

bool looks_like_pcd(std::string_view head) {
  if (!(starts_with(head, "#") || starts_with(head, "VERSION") || starts_with(head, "FIELDS"))) {
    return false;
  }
  return head.find("FIELDS") != std::string_view::npos;
}

std::unique_ptr<ScanSource> open_by_content(const std::string& input,
                                            const SourceOptions& options) {
  std::error_code ec;
  const fs::file_status status = fs::status(input, ec);
  if (ec || !fs::exists(status)) throw InputError(input + ": no such file or folder");
  if (fs::is_directory(status)) {
    // rosbag2 writes metadata.yaml beside the files of every bag it closes.
    if (fs::is_regular_file(fs::path(input) / "metadata.yaml"))
      return open_ros2_bag(input, options);
    return open_scan_folder(input, options);
  }
  if (fs::path(input).filename() == "metadata.yaml") {
    return open_ros2_bag(fs::path(input).parent_path().string(), options);
  }
  if (!fs::is_regular_file(status)) throw InputError(input + ": not a regular file");

  std::ifstream file(input, std::ios::binary);
  if (!file) throw InputError(input + ": cannot open (permission denied?)");
  std::string head(1024, '\0');
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(file.gcount()));
  if (head.empty()) throw InputError(input + ": empty file");

  if (head.size() >= 4) {
    uint32_t magic = 0;
    std::memcpy(&magic, head.data(), 4);
    if (magic == 0xa1b2c3d4u || magic == 0xd4c3b2a1u || magic == 0xa1b23c4du ||
        magic == 0x4d3cb2a1u) {
      if (is_velodyne_pcap(input)) return open_velodyne_pcap(input, options);
      return open_ouster_pcap(input, options);
    }
    if (magic == 0x0a0d0d0au) {
      throw InputError(input +
                       ": a pcapng capture; save it as classic pcap (editcap -F pcap IN OUT)");
    }
  }
  if (starts_with(head, "#ROSBAG V2.0")) return open_rosbag(input, options);
  if (starts_with(head, std::string_view("SQLite format 3\0", 16))) {
    return open_ros2_bag(input, options);
  }
  if (starts_with(head, std::string_view("\x89MCAP0\r\n", 8))) return open_mcap(input, options);
  if (starts_with(head, "#ROSBAG")) {
    throw InputError(input + ": only ROS bag format 2.0 is supported (ROS 1 bags)");
  }
  if (starts_with(head, "ply\n") || starts_with(head, "ply\r\n")) {
    return open_ply_file(input, options);
  }
  if (looks_like_pcd(head)) return open_pcd_file(input, options);
  if (fs::path(input).extension() == ".bin") {
    throw InputError(input + ": a single KITTI .bin; pass the folder that holds the scans");
  }
  throw InputError(input +
                   ": unrecognised format (expected an Ouster or Velodyne pcap, a ROS1 bag, a "
                   "ROS 2 bag folder or .db3, an MCAP file, a PCD or PLY file, or a folder of "
                   "scans)");
}

}  // namespace

std::unique_ptr<ScanSource> open_scan_source(const std::string& input,
                                             const SourceOptions& options) {
  return with_range_limits(open_by_content(input, options), options);
}

std::unique_ptr<ScanSource> with_range_limits(std::unique_ptr<ScanSource> source,
                                              const SourceOptions& options) {
  const config::SensorModel& sensor = source->info().sensor;
  const double min_m = options.min_range_m.value_or(sensor.min_range_m);
  const double max_m =
      options.max_range_m.value_or(sensor.max_range_m > 0.0 ? sensor.max_range_m : 1.0e9);
  return with_range_limits(std::move(source), min_m, max_m, options.self_box);
}

std::unique_ptr<ScanSource> with_range_limits(
    std::unique_ptr<ScanSource> source, double min_m, double max_m,
    const std::optional<std::array<double, 6>>& self_box) {
  return std::make_unique<RangeLimitedSource>(std::move(source), min_m, max_m, self_box);
}

}  // namespace featsense::slam
