#include "featsense/slam/sim/simulated_scan_source.hpp"

#include <utility>

namespace featsense::slam {

SimulatedScanSource::SimulatedScanSource(const LidarSimulator& simulator,
                                         const mesh::TriangleMesh& scene, const PoseCurve& path,
                                         uint64_t frames, const std::string& description,
                                         const std::string& ground_truth_dir)
    : simulator_(simulator),
      scene_(scene),
      path_(path),
      frames_(frames),
      ground_truth_(ground_truth_dir, simulator.settings().sensor, 0.02, false) {
  info_.format = "simulated";
  info_.path = description;
  info_.sensor = simulator.settings().sensor;
  info_.sensor_from_metadata = true;
  info_.frames = frames;
  info_.fields = {"x", "y", "z", "intensity", "reflectivity", "t"};
  info_.times = "per column, simulated";
  info_.imu = "simulated, riding with the sensor";
}

std::optional<Scan> SimulatedScanSource::next() {
  if (next_frame_ >= frames_) {
    if (!finished_) {
      ground_truth_.finish(scene_);
      finished_ = true;
    }
    return std::nullopt;
  }
  SimulatedFrame frame = simulator_.simulate(next_frame_);
  ground_truth_.add(frame, path_.pose(frame.start_s));
  frame.scan.sequence = next_frame_++;
  count_frame();
  return std::move(frame.scan);
}

}  // namespace featsense::slam
