#pragma once
// A scan's points as the localizer registers them: one per voxel, each with the time it was
// measured, so that the scan can be deskewed again for any motion over the sweep without
// going back to its hundred thousand points. The tracking deskews with the predicted motion,
// registers, and deskews again with the motion the registration found: a scan deskewed by a
// wrong velocity is stretched along it, and its best fit is shifted by half the stretch, which
// the next prediction would take for speed.

#include <Eigen/Core>

#include <vector>

#include "featsense/slam/refine/gaussian_cloud.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"

namespace featsense::mapping {

struct TimedScanCloud {
  /// In the sensor's frame at the time each was measured (not deskewed), with the
  /// covariances of their neighbourhoods (a sweep's motion bends a neighbourhood far less
  /// than a voxel).
  slam::refine::GaussianCloud measured;
  std::vector<double> times_s;  ///< per point: the mean of its voxel's times after the stamp
};

/// The centroids of the scan's valid points per voxel of `voxel_m` in the sensor's frame (the
/// points of one voxel are measured within a few columns of each other), with covariances
/// from `neighbours` nearest; at most `max_points` of them, spread evenly over the voxels in
/// the order of their keys (every k-th).
TimedScanCloud timed_scan_cloud(const slam::Scan& scan, double voxel_m, int neighbours,
                                size_t max_points);

/// The cloud in the sensor's frame at the stamp: each point moved by `sweep` at its time.
slam::refine::GaussianCloud deskewed(const TimedScanCloud& cloud, const slam::SweepMotion& sweep);

}  // namespace featsense::mapping
