#pragma once
/// The local feature map around the sensor: edge and surface points in the map frame, one
/// per voxel (odometry.edge_voxel / surface_voxel), those farther than odometry.map_radius
/// from the sensor dropped. Each scan adds its features and prunes the map once registered.
/// The points are searched in nanoflann's logarithmic k-d trees (static trees of 1, 2, 4 ...
/// points): a scan's new points are merged in and the dropped ones marked removed, so that a
/// scan costs what it changed rather than a tree over the whole map, as F-LOAM rebuilds.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace featsense::slam::odometry {

class LocalFeatureMap {
 public:
  LocalFeatureMap(double edge_voxel_m, double surface_voxel_m, double radius_m);
  ~LocalFeatureMap();
  LocalFeatureMap(const LocalFeatureMap&) = delete;
  LocalFeatureMap& operator=(const LocalFeatureMap&) = delete;

  /// Adds a scan's features (sensor frame) at `T_map_sensor` (a point goes in where its voxel
  /// is still free) and drops what lies farther than the radius from the sensor.
  void add(const std::vector<Eigen::Vector3f>& edges, const std::vector<Eigen::Vector3f>& surfaces,
           const Eigen::Isometry3d& T_map_sensor);

  /// The k nearest edge (surface) points of `query` that lie within `max_distance_m`, nearest
  /// first, into `found` (cleared first; the caller's buffer, so that searches allocate
  /// nothing); fewer when the map has fewer there.
  void nearest_edges(const Eigen::Vector3d& query, int k, double max_distance_m,
                     std::vector<Eigen::Vector3d>& found) const;
  void nearest_surfaces(const Eigen::Vector3d& query, int k, double max_distance_m,
                        std::vector<Eigen::Vector3d>& found) const;

  size_t edge_count() const;
  size_t surface_count() const;
  bool empty() const { return edge_count() + surface_count() == 0; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace featsense::slam::odometry
