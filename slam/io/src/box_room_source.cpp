#include "featsense/slam/io/box_room_source.hpp"

#include <cmath>
#include <limits>

namespace featsense::slam {
namespace {

/// Distance along unit direction `d` from `p` (inside the box) to the box's surface.
double distance_to_box_wall(const Eigen::Vector3d& p, const Eigen::Vector3d& d,
                            const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (d[axis] > 0.0) t = std::min(t, (hi[axis] - p[axis]) / d[axis]);
    if (d[axis] < 0.0) t = std::min(t, (lo[axis] - p[axis]) / d[axis]);
  }
  return t;
}

class BoxRoomSource final : public ScanSource {
 public:
  explicit BoxRoomSource(BoxRoomSettings settings) : settings_(std::move(settings)) {
    settings_.sensor.validate();
    info_.format = "builtin-box-room";
    info_.path = "builtin:box-room";
    info_.sensor = settings_.sensor;
    info_.sensor_from_metadata = true;
    info_.frames = static_cast<size_t>(settings_.frames);
    info_.fields = {"x", "y", "z", "range", "t"};
    info_.detail = "analytic scans of an empty box room, sensor moving in a straight line";
    info_.times = "per column, simulated";
  }

  std::optional<Scan> next() override {
    if (frame_ >= settings_.frames) return std::nullopt;
    const config::SensorModel& s = settings_.sensor;
    const double period_s = 1.0 / s.rate_hz;
    const double frame_start_s = frame_ * period_s;
    Scan scan = Scan::allocate(s.beams, s.columns);
    scan.sequence = static_cast<uint64_t>(frame_);
    scan.stamp_ns =
        settings_.start_stamp_ns + static_cast<int64_t>(std::llround(frame_start_s * 1e9));
    for (int col = 0; col < s.columns; ++col) {
      const double offset_s = period_s * col / s.columns;
      const Eigen::Vector3d origin =
          box_room_pose(settings_, frame_start_s + offset_s).translation();
      // Clockwise from +x, as the sensors spin (scan.hpp).
      const double column_azimuth = -2.0 * M_PI * col / s.columns;
      for (int row = 0; row < s.beams; ++row) {
        const double azimuth = column_azimuth + s.azimuth_offset_rad[static_cast<size_t>(row)];
        const double elevation = s.elevation_rad[static_cast<size_t>(row)];
        const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
        const double range =
            distance_to_box_wall(origin, d, settings_.room_min_m, settings_.room_max_m);
        if (!(range >= s.min_range_m && range <= s.max_range_m)) continue;
        const size_t i = scan.index(row, col);
        scan.xyz[i] = (range * d).cast<float>();  // the sensor does not rotate
        scan.range_m[i] = static_cast<float>(range);
        scan.time_offset_s[i] = static_cast<float>(offset_s);
        scan.valid[i] = 1;
      }
    }
    ++frame_;
    count_frame();
    return scan;
  }

  const SourceInfo& info() const override { return info_; }

 private:
  BoxRoomSettings settings_;
  SourceInfo info_;
  int frame_ = 0;
};

}  // namespace

BoxRoomSettings default_box_room() {
  BoxRoomSettings settings;
  settings.sensor = config::sensor_preset("os1-128");
  return settings;
}

Eigen::Isometry3d box_room_pose(const BoxRoomSettings& settings, double seconds) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = settings.start_m + seconds * settings.velocity_mps;
  return pose;
}

std::unique_ptr<ScanSource> make_box_room_source(const BoxRoomSettings& settings) {
  return std::make_unique<BoxRoomSource>(settings);
}

}  // namespace featsense::slam
