#pragma once
// A simulation as a scan source: frames go straight from the simulator to the mapping run,
// and only the ground truth (gt_trajectory.tum, gt_mesh.ply, gt_points.ply) is written, once
// the last frame was handed out. A demo thus needs no recording on disk.

#include <cstdint>
#include <optional>
#include <string>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"
#include "featsense/slam/sim/trajectory.hpp"

namespace featsense::slam {

class SimulatedScanSource final : public ScanSource {
 public:
  /// Frames 0 .. frames-1 of `simulator` (which casts into `scene` along `path`; all three must
  /// outlive the source); the ground truth goes to `ground_truth_dir`.
  SimulatedScanSource(const LidarSimulator& simulator, const mesh::TriangleMesh& scene,
                      const PoseCurve& path, uint64_t frames, const std::string& description,
                      const std::string& ground_truth_dir);

  std::optional<Scan> next() override;
  const SourceInfo& info() const override { return info_; }

 private:
  const LidarSimulator& simulator_;
  const mesh::TriangleMesh& scene_;
  const PoseCurve& path_;
  uint64_t frames_;
  SourceInfo info_;
  SimulationWriter ground_truth_;
  uint64_t next_frame_ = 0;
  bool finished_ = false;
};

}  // namespace featsense::slam
