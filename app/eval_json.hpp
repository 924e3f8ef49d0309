#pragma once
// The JSON form of evaluation results, shared by `featsense eval` and the reports of `map`
// and `demo` (keys listed in DESIGN.md, "Names that scripts rely on").

#include <nlohmann/json.hpp>

#include "featsense/mesh/compare_to_reference.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::app {

/// `pairs`, `ape`, `rpe` (per frame; translation m, with `rotation_deg`), `kitti` (only when a
/// 100 m segment fits), `alignment`, `association`.
nlohmann::json trajectory_evaluation_json(const slam::TrajectoryEvaluation& evaluation,
                                          const slam::TrajectoryEvaluationSettings& settings);

/// `points`, `accuracy` (m), `completeness`, `precision`, `fscore` (keyed "0.02", "0.05",
/// "0.10"), `histogram`, and how the reference was sampled.
nlohmann::json mesh_comparison_json(const mesh::CompareResult& result,
                                    const mesh::CompareSettings& settings);

}  // namespace featsense::app
