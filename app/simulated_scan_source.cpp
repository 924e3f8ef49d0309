#include "simulated_scan_source.hpp"

namespace featsense::app {

SimulatedScanSource::SimulatedScanSource(const PreparedSimulation& simulation,
                                         const std::string& description,
                                         const std::string& ground_truth_dir)
    : simulation_(simulation),
      ground_truth_(ground_truth_dir, simulation.simulator->settings().sensor, 0.02, false) {
  info_.format = "simulated";
  info_.path = description;
  info_.sensor = simulation.simulator->settings().sensor;
  info_.sensor_from_metadata = true;
  info_.frames = simulation.frames;
  info_.fields = {"x", "y", "z", "intensity", "reflectivity", "t"};
  info_.times = "per column, simulated";
  info_.imu = "simulated, riding with the sensor";
}

std::optional<slam::Scan> SimulatedScanSource::next() {
  if (next_frame_ >= simulation_.frames) {
    if (!finished_) {
      ground_truth_.finish(simulation_.mesh);
      finished_ = true;
    }
    return std::nullopt;
  }
  slam::SimulatedFrame frame = simulation_.simulator->simulate(next_frame_);
  ground_truth_.add(frame, simulation_.trajectory->pose(frame.start_s));
  frame.scan.sequence = next_frame_++;
  count_frame();
  return std::move(frame.scan);
}

}  // namespace featsense::app
