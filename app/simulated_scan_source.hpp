#pragma once
// A simulation as a scan source: frames go straight from the simulator to the pipeline, and
// only the ground truth (gt_trajectory.tum, gt_mesh.ply, gt_points.ply) is written, once the
// last frame was handed out. A demo thus needs no recording on disk.

#include <memory>
#include <string>

#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"
#include "simulate_job.hpp"

namespace featsense::app {

class SimulatedScanSource final : public slam::ScanSource {
 public:
  /// `simulation` must outlive the source; the ground truth goes to `ground_truth_dir`.
  SimulatedScanSource(const PreparedSimulation& simulation, const std::string& description,
                      const std::string& ground_truth_dir);

  std::optional<slam::Scan> next() override;
  const slam::SourceInfo& info() const override { return info_; }

 private:
  const PreparedSimulation& simulation_;
  slam::SourceInfo info_;
  slam::SimulationWriter ground_truth_;
  uint64_t next_frame_ = 0;
  bool finished_ = false;
};

}  // namespace featsense::app
