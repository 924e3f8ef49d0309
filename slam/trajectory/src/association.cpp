// Pairs poses by nearest stamp within a tolerance (evo's rule), or by index without stamps.

#include "featsense/slam/trajectory/association.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace featsense::slam {
namespace {

std::string range_text(const Trajectory& t, double offset_s) {
  char text[96];
  std::snprintf(text, sizeof text, "[%.6f, %.6f] s",
                1e-9 * static_cast<double>(t.stamps_ns.front()) + offset_s,
                1e-9 * static_cast<double>(t.stamps_ns.back()) + offset_s);
  return text;
}

/// Index of the stamp in `sorted` nearest to `stamp_s` (seconds, `sorted` in ns + offset).
size_t nearest(const std::vector<int64_t>& sorted, double offset_s, double stamp_s,
               double* diff_s) {
  const int64_t target = std::llround((stamp_s - offset_s) * 1e9);
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), target);
  size_t best = 0;
  double best_diff = INFINITY;
  for (auto candidate : {it, it == sorted.begin() ? it : it - 1}) {
    if (candidate == sorted.end()) continue;
    const double d = std::abs(1e-9 * static_cast<double>(*candidate) + offset_s - stamp_s);
    if (d < best_diff) {
      best_diff = d;
      best = static_cast<size_t>(candidate - sorted.begin());
    }
  }
  *diff_s = best_diff;
  return best;
}

}  // namespace

Association associate(const Trajectory& estimate, const Trajectory& ground_truth,
                      const AssociationSettings& settings) {
  if (estimate.empty()) throw TrajectoryError("the estimated trajectory is empty");
  if (ground_truth.empty()) throw TrajectoryError("the ground-truth trajectory is empty");
  Association result;
  if (!estimate.has_stamps || !ground_truth.has_stamps) {
    if (estimate.size() != ground_truth.size()) {
      throw TrajectoryError(
          "a trajectory without time stamps (KITTI) is paired by index, but the estimate has " +
          std::to_string(estimate.size()) + " poses and the ground truth " +
          std::to_string(ground_truth.size()) + " (give a times file, or TUM files)");
    }
    result.by_index = true;
    for (size_t i = 0; i < estimate.size(); ++i) {
      result.estimate_index.push_back(i);
      result.ground_truth_index.push_back(i);
    }
    return result;
  }
  const double offset = settings.offset_s;
  const double est_begin = 1e-9 * static_cast<double>(estimate.stamps_ns.front()) + offset;
  const double est_end = 1e-9 * static_cast<double>(estimate.stamps_ns.back()) + offset;
  const double gt_begin = 1e-9 * static_cast<double>(ground_truth.stamps_ns.front());
  const double gt_end = 1e-9 * static_cast<double>(ground_truth.stamps_ns.back());
  if (est_end + settings.max_diff_s < gt_begin || gt_end + settings.max_diff_s < est_begin) {
    throw TrajectoryError("the time ranges do not overlap: estimate " +
                          range_text(estimate, offset) + ", ground truth " +
                          range_text(ground_truth, 0.0) +
                          " (wrong file, or a time offset to give)");
  }
  // The shorter trajectory picks its partner in the longer one, as evo does.
  const bool estimate_shorter = estimate.size() <= ground_truth.size();
  const Trajectory& shorter = estimate_shorter ? estimate : ground_truth;
  const Trajectory& longer = estimate_shorter ? ground_truth : estimate;
  const double shorter_offset = estimate_shorter ? offset : 0.0;
  const double longer_offset = estimate_shorter ? 0.0 : offset;
  for (size_t i = 0; i < shorter.size(); ++i) {
    const double stamp_s = 1e-9 * static_cast<double>(shorter.stamps_ns[i]) + shorter_offset;
    double diff = 0.0;
    const size_t j = nearest(longer.stamps_ns, longer_offset, stamp_s, &diff);
    if (diff > settings.max_diff_s) continue;
    result.estimate_index.push_back(estimate_shorter ? i : j);
    result.ground_truth_index.push_back(estimate_shorter ? j : i);
    result.max_stamp_diff_s = std::max(result.max_stamp_diff_s, diff);
  }
  if (result.size() == 0) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "no pose pair within %.6f s of each other (raise the tolerance, or give the "
                  "time offset between the clocks)",
                  settings.max_diff_s);
    throw TrajectoryError(text);
  }
  return result;
}

}  // namespace featsense::slam
