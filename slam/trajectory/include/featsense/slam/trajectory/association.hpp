#pragma once
/// Pairs of poses of two trajectories that describe the same instant.
///
/// As evo's `associate_trajectories`: for every pose of the shorter trajectory, the pose of
/// the longer one with the nearest stamp (after adding `offset_s` to the estimate's stamps,
/// as evo's --t_offset) is taken if it is at most `max_diff_s` away. A pose of the longer
/// trajectory may thus serve twice when the shorter one is sampled faster than the tolerance.
/// Trajectories without stamps (KITTI without times) are paired by index and must have the same
/// length.

#include <utility>
#include <vector>

#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

struct AssociationSettings {
  double max_diff_s = 0.01;  ///< largest stamp difference of a pair, seconds (evo's default)
  double offset_s = 0.0;     ///< added to the estimate's stamps before matching, seconds
};

struct Association {
  std::vector<size_t> estimate_index;      ///< per pair, index into the estimate
  std::vector<size_t> ground_truth_index;  ///< per pair, index into the ground truth
  double max_stamp_diff_s = 0.0;           ///< largest |difference| among the pairs, seconds
  bool by_index = false;                   ///< true when paired by index (no stamps)

  size_t size() const { return estimate_index.size(); }
};

/// Throws TrajectoryError when either trajectory is empty, their time ranges do not overlap,
/// no pair is found, or (by index) their lengths differ; each message says what to change.
Association associate(const Trajectory& estimate, const Trajectory& ground_truth,
                      const AssociationSettings& settings = {});

}  // namespace featsense::slam
