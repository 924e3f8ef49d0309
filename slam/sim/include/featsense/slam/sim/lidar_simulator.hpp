#pragma once
/// A spinning LiDAR moving through a triangle mesh: one organized Scan per revolution,
/// each column fired at its own time along the trajectory.

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <vector>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/sim/imu_simulator.hpp"
#include "featsense/slam/sim/measurement_model.hpp"
#include "featsense/slam/sim/ray_caster.hpp"
#include "featsense/slam/sim/trajectory.hpp"

namespace featsense::slam {

struct SimulationSettings {
  config::SensorModel sensor;
  MeasurementSettings measurement;
  /// The IMU riding with the LiDAR (its samples go with each frame); its noise draws use
  /// measurement.seed.
  ImuModel imu;
  int64_t start_stamp_ns = 1'700'000'000'000'000'000;  ///< stamp of frame 0
};

/// One simulated revolution.
struct SimulatedFrame {
  /// Sensor frame at each column's own time; channels "reflectivity" (0..100 %) and
  /// "intensity"; range_m measured from the lidar origin (beam origin offset included); the
  /// IMU's samples during the revolution.
  Scan scan;
  double start_s = 0.0;  ///< trajectory time of column 0, seconds
  /// Noise-free surface points that the valid returns came from (map frame, metres).
  std::vector<Eigen::Vector3f> surface_points_m;
};

class LidarSimulator {
 public:
  /// The caster and trajectory must outlive the simulator. Throws ConfigError for an
  /// inconsistent sensor.
  LidarSimulator(const mesh::TriangleMesh& mesh, const RayCaster& caster,
                 const PoseCurve& trajectory, SimulationSettings settings);

  /// Frame `index` (0-based): column c is fired at trajectory time
  /// (index + c / columns) / rate_hz seconds.
  SimulatedFrame simulate(uint64_t index) const;
  /// How many whole revolutions fit into the trajectory.
  uint64_t frames_available() const;
  const SimulationSettings& settings() const { return settings_; }

 private:
  const mesh::TriangleMesh& mesh_;
  const RayCaster& caster_;
  const PoseCurve& trajectory_;
  SimulationSettings settings_;
  // Per cell (row-major), sensor frame: beam origins (m) and unit directions, computed once.
  std::vector<Eigen::Vector3d> local_origin_;
  std::vector<Eigen::Vector3d> local_direction_;
};

/// The sensor-frame direction of beam `row` in column `col` (unit vector) and the beam's
/// origin (metres): column c looks along azimuth -2 pi c / columns plus the beam's azimuth
/// offset, its origin lies beam_origin_offset_m out along the column's azimuth (Ouster).
void beam_geometry(const config::SensorModel& sensor, int row, int col, Eigen::Vector3d* origin,
                   Eigen::Vector3d* direction);

/// Throws std::invalid_argument naming the time and position when the sensor leaves the
/// mesh's bounding box (grown by margin_m) at some time in [0, end_s] (checked every
/// step_s seconds and at end_s).
void check_trajectory_inside(const PoseCurve& trajectory, const mesh::TriangleMesh& mesh,
                             double end_s, double step_s = 0.01, double margin_m = 0.0);

}  // namespace featsense::slam
