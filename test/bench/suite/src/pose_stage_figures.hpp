#pragma once
// bench odometry's figures of what comes after the odometry: the trajectory's error against
// the truth, the refinement's and the loop closure's figures, a wrong loop injected on purpose.

#include <nlohmann/json.hpp>

#include <optional>

#include "featsense/mapping/loop_stage.hpp"
#include "featsense/mapping/pass_result.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/refine/segment_refiner.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::bench {

/// The trajectory's error against the truth into `out` (nothing where it is undetermined).
void add_trajectory_error(const slam::Trajectory& estimate, const slam::Trajectory& truth,
                          nlohmann::json& out);

/// The refinement's figures: stretches, what was kept and why, its cost per scan and per
/// stretch against the time the stretch took to record, the corrections.
nlohmann::json bench_refine_json(const mapping::PassResult& run,
                                 const slam::refine::RefineSettings& settings);

/// The loop closure's figures: counts and times; with the truth, each loop's measured pose
/// against it.
nlohmann::json bench_loops_json(const mapping::LoopOutcome& outcome,
                                const slam::loops::LoopCloser& closer,
                                const std::optional<slam::Trajectory>& truth);

/// Adds a deliberately wrong loop to the finished graph of `closer` and optimises it: what
/// the claim is off by against the truth, and the weight the robust loss left it.
nlohmann::json inject_wrong_loop(slam::loops::LoopCloser& closer,
                                 const std::optional<slam::Trajectory>& truth);

}  // namespace featsense::bench
