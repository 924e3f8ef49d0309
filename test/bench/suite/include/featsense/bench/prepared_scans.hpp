#pragma once
// The scans the benchmarks integrate: built-in OS1-128 scans of an analytic scene, or the
// first frames of a recording.

#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::bench {

/// Scans as rays in the map frame, ready to integrate.
struct PreparedScans {
  std::vector<tsdf::RayBatch> rays;
  config::SensorModel sensor;
  std::string description;
  size_t input_points = 0;
};

/// `count` scans of an OS1-128 moving through a 20 x 20 x 4 m room ("indoor") or through a
/// 120 x 80 m yard open to the sky ("outdoor": outdoor ranges, beams above the horizon lost).
PreparedScans prepare_builtin(const std::string& scene, int count);

/// The first `count` frames of a recording, each at the origin; `name` says which in the
/// description and the error. Throws slam::InputError when it gave no frame.
PreparedScans prepare_recording(slam::ScanSource& source, const std::string& name, int count);

}  // namespace featsense::bench
