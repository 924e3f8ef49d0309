#pragma once
/// Turns an unorganized cloud into the organized Scan layout of scan.hpp.

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/point_cloud.hpp"
#include "featsense/slam/scan.hpp"

namespace featsense::slam {

struct OrganizeStats {
  size_t input_points = 0;
  size_t dropped_invalid = 0;     ///< zero, NaN or infinite points
  size_t dropped_outside = 0;     ///< ring or elevation outside the sensor's beams
  size_t dropped_collisions = 0;  ///< a second point for an occupied cell (the nearer is kept)
};

/// Places each point in the cell of its beam (the ring field where the cloud has one,
/// else the beam of the sensor whose elevation is nearest to the point's) and its column
/// (azimuth, clockwise from +x, sensor.columns per revolution). Zero / NaN points are
/// dropped, never data. Rows of the result = sensor.beams, cols = sensor.columns.
Scan organize(const PointCloud& cloud, const config::SensorModel& sensor,
              OrganizeStats* stats = nullptr);

/// The column of a direction: azimuth measured clockwise from +x, in [0, columns).
int column_of(const Eigen::Vector3f& xyz, int columns);

}  // namespace featsense::slam
