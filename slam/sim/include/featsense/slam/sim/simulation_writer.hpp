#pragma once
/// The output folder of `featsense simulate` (a recording the readers open, see
/// slam/io/src/cloud/SEQUENCE_FORMAT.md) and its ground truth:
///   frame_NNNNNN.pcd    one organized binary PCD per frame (ring, t, intensity channels)
///   sequence.yaml       index of the frames and the sensor
///   imu.csv             the IMU's samples of every frame (where the frames carry any)
///   gt_trajectory.tum   T_map_sensor per frame at its stamp (column 0's time)
///   gt_mesh.ply         the scene's triangles, binary PLY
///   gt_points.ply       the noise-free surface points the sensor saw, over all frames,
///                       thinned to one per voxel_size_m cube (the first seen), binary PLY
///                       grouped in 32 m tiles with their index in the header, read by
///                       region (mesh/tiled_point_file.hpp); memory stays bounded however
///                       long the route

#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "featsense/config/sensor_model.hpp"
#include "featsense/mesh/tiled_point_file.hpp"
#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/trajectory.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

class SimulationWriter {
 public:
  /// Creates `folder` (and parents). Throws WriteError naming it when that fails. Without
  /// `write_frames` only the ground truth is written (the frames went straight to a consumer).
  SimulationWriter(std::string folder, config::SensorModel sensor, double voxel_size_m = 0.02,
                   bool write_frames = true);

  /// Writes the frame's PCD and records its stamp, ground-truth pose and surface points.
  void add(const SimulatedFrame& frame, const Eigen::Isometry3d& T_map_sensor);
  /// Writes gt_trajectory.tum, gt_mesh.ply, gt_points.ply and (with frames) sequence.yaml
  /// and imu.csv.
  void finish(const mesh::TriangleMesh& mesh);

  size_t ground_truth_points() const { return points_.points(); }

 private:
  std::string folder_;
  config::SensorModel sensor_;
  bool write_frames_;
  std::vector<std::string> files_;
  std::vector<int64_t> stamps_ns_;
  std::string imu_csv_;  ///< the lines of imu.csv so far, header excluded
  bool imu_written_ = false;
  int64_t last_imu_stamp_ns_ = 0;  ///< of the latest line of imu_csv_
  Trajectory trajectory_;          ///< the true pose of each frame at its stamp
  mesh::TiledPointWriter points_;  ///< gt_points.ply
};

/// Binary little-endian PLY of the mesh's vertices and triangles (metres). Throws WriteError.
void write_mesh_ply(const mesh::TriangleMesh& mesh, const std::string& path);

}  // namespace featsense::slam
