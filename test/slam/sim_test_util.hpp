#pragma once
// Small sensors and an analytic box room for the simulator's tests.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "featsense/config/sensor_model.hpp"
#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"

namespace featsense::test {

/// 32 beams, unevenly spaced from +15 to -16 deg, each with its own azimuth offset, 256
/// columns at 10 Hz, an Ouster-like beam origin offset.
inline config::SensorModel small_sensor() {
  config::SensorModel s;
  s.name = "test-32";
  s.beams = 32;
  s.columns = 256;
  s.rate_hz = 10.0;
  for (int b = 0; b < s.beams; ++b) {
    const double deg = 15.0 - 31.0 * std::pow(b / 31.0, 1.2);
    s.elevation_rad.push_back(deg * M_PI / 180.0);
    s.azimuth_offset_rad.push_back(((b % 4) - 1.5) * 0.01);
  }
  s.beam_origin_offset_m = 0.015;
  s.min_range_m = 0.3;
  s.max_range_m = 60.0;
  return s;
}

struct Box {
  Eigen::Vector3d lo{-5.0, -4.0, 0.0};
  Eigen::Vector3d hi{6.0, 4.0, 3.0};
};

inline mesh::TriangleMesh box_mesh(const Box& box) {
  mesh::TriangleMesh mesh;
  const uint32_t part = mesh.add_part("wall", 0.6f);
  mesh.add_box(box.lo.cast<float>(), box.hi.cast<float>(), part);
  return mesh;
}

/// A walk through the box room, (-2, -1, 1.4) to (2, 1, 1.6) m in one second, and what a
/// simulator of it refers to: the simulator must not outlive the walk.
struct BoxRoomWalk {
  Box box;
  mesh::TriangleMesh mesh = box_mesh(box);
  slam::RayCaster caster{mesh};
  std::unique_ptr<slam::PoseCurve> trajectory =
      slam::make_spline_trajectory({Eigen::Vector3d(-2, -1, 1.4), Eigen::Vector3d(2, 1, 1.6)}, 1.0);

  slam::LidarSimulator simulator(const slam::SimulationSettings& settings) const {
    return slam::LidarSimulator(mesh, caster, *trajectory, settings);
  }
};

/// Distance of a point to the nearest face plane of the box (the point is inside).
inline double distance_to_box(const Eigen::Vector3d& p, const Box& box) {
  double d = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k)
    d = std::min({d, std::abs(p[k] - box.lo[k]), std::abs(p[k] - box.hi[k])});
  return d;
}

}  // namespace featsense::test
