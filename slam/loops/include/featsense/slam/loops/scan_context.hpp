#pragma once
/// A place descriptor of one spinning-LiDAR scan: Scan Context (Kim and Kim, IROS 2018). The
/// ground plane around the sensor is cut into rings (by range) and sectors (by azimuth); each
/// bin holds the height of the highest point in it above the scan's ground. A revisit seen
/// with another heading gives the same matrix with its sectors turned: the distance between
/// two descriptors is the best over all column shifts, and that shift is the relative yaw.
/// The ring key (the occupancy of each ring) does not depend on the heading: it picks the
/// candidates cheaply.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace featsense::slam::loops {

struct ScanContextSettings {
  int rings = 20;
  int sectors = 60;
  double max_range_m = 80.0;
  /// Points closer than this are the vehicle or the person carrying the sensor.
  double min_range_m = 1.0;
};

struct ScanContext {
  int rings = 0;
  int sectors = 0;
  /// rings x sectors, row major: height of the highest point above the ground, metres (0:
  /// empty bin).
  std::vector<float> bins;
  /// Per ring, the fraction of its sectors that hold a point.
  std::vector<float> ring_key;

  float at(int ring, int sector) const {
    return bins[static_cast<size_t>(ring * sectors + sector)];
  }
  bool empty() const { return bins.empty(); }
};

/// The descriptor of `points` given in a levelled frame at the sensor (x forward, z up:
/// the sensor's frame turned by its roll and pitch, so that a tilted sensor sees the same
/// place). The ground is the 5th percentile of the heights within 20 m.
ScanContext make_scan_context(const std::vector<Eigen::Vector3f>& levelled_points,
                              const ScanContextSettings& settings = {});

/// A descriptor kept as its bins (a map file's): the ring key is made from them. Throws
/// std::invalid_argument where the bins are not rings x sectors finite values.
ScanContext scan_context_from_bins(int rings, int sectors, std::vector<float> bins);

/// The sensor frame turned so that z is up, the heading kept: points p of the sensor frame go
/// to levelling(T_map_sensor) * p.
Eigen::Matrix3d levelling(const Eigen::Isometry3d& T_map_sensor);

struct ScanContextMatch {
  double distance = 1.0;  ///< 0 (the same) .. 1 (nothing alike)
  /// The yaw of the query's sensor in the candidate's frame (radians, the candidate's
  /// heading + yaw = the query's heading).
  double yaw_rad = 0.0;
};

/// The distance between two descriptors of the same size: the mean cosine distance of the
/// sector columns that hold points in either, at the best column shift.
ScanContextMatch match(const ScanContext& query, const ScanContext& candidate);

/// The descriptor of `points` (sensor frame) taken by a sensor at `T_map_sensor`: turned into
/// its levelled frame first.
ScanContext levelled_scan_context(const Eigen::Isometry3d& T_map_sensor,
                                  const std::vector<Eigen::Vector3f>& points,
                                  const ScanContextSettings& settings);

/// The pose of the query's sensor in the candidate's (candidate <- query) that a match says:
/// turned by the match's yaw between the two levelled frames, no translation ("the same
/// place"), from the two sensors' poses in their own maps.
Eigen::Isometry3d descriptor_guess(const Eigen::Isometry3d& T_map_candidate,
                                   const Eigen::Isometry3d& T_map_query, double yaw_rad);

/// The L2 distance of the ring keys.
double ring_key_distance(const ScanContext& a, const ScanContext& b);

}  // namespace featsense::slam::loops
