#include "featsense/bench/prepared_scans.hpp"

#include <optional>

#include "featsense/mapping/scan_to_rays.hpp"
#include "featsense/slam/io/box_room_source.hpp"

namespace featsense::bench {

PreparedScans prepare_builtin(const std::string& scene, int count) {
  slam::BoxRoomSettings settings = slam::default_box_room();
  settings.frames = count;
  if (scene == "outdoor") {
    settings.room_min_m = Eigen::Vector3d(-60, -40, 0);
    settings.room_max_m = Eigen::Vector3d(60, 40, 1e4);
    settings.velocity_mps = Eigen::Vector3d(5, 0, 0);
  }
  PreparedScans prepared;
  prepared.sensor = settings.sensor;
  prepared.description = "built-in " + scene + " scene, os1-128 1024 x 128, moving sensor";
  auto source = slam::make_box_room_source(settings);
  int frame = 0;
  while (auto scan = source->next()) {
    const double frame_start = frame / settings.sensor.rate_hz;
    slam::ScanPlacement placement;
    placement.T_map_sensor = slam::box_room_pose(settings, frame_start);
    placement.column_T_map_sensor =
        slam::column_poses(*scan, placement.T_map_sensor, [&](double t) {
          return std::optional<Eigen::Isometry3d>(slam::box_room_pose(settings, frame_start + t));
        });
    prepared.rays.push_back(mapping::scan_to_rays(*scan, placement));
    prepared.input_points += prepared.rays.back().size();
    ++frame;
  }
  return prepared;
}

PreparedScans prepare_recording(slam::ScanSource& source, const std::string& name, int count) {
  PreparedScans prepared;
  prepared.sensor = source.info().sensor;
  prepared.description = source.info().format + " " + name + " (frames at the origin)";
  while (static_cast<int>(prepared.rays.size()) < count) {
    std::optional<slam::Scan> scan = source.next();
    if (!scan) break;
    prepared.rays.push_back(mapping::scan_to_rays(*scan, slam::ScanPlacement{}));
    prepared.input_points += prepared.rays.back().size();
  }
  if (prepared.rays.empty()) throw slam::InputError(name + ": no readable frame");
  return prepared;
}

}  // namespace featsense::bench
