#include "featsense/mapping/map_policy.hpp"

#include <cstdio>

namespace featsense::mapping {

bool moves_the_map(double moved_m, double voxel_size_m) { return moved_m > 0.25 * voxel_size_m; }

SecondPassOutcome plan_second_pass(const LoopOutcome* loops, bool interrupted, bool integrate,
                                   bool replayable, double voxel_size_m) {
  if (!loops || !loops->corrects_poses())
    return {SecondPass::kNotNeeded, "no loop closed, no gravity"};
  // Levelled by gravity alone, the poses may move less than the map can show: then the first
  // map stays (a second pass would double the run for nothing).
  const bool levelled_only = loops->loops.empty();
  if (levelled_only && !moves_the_map(loops->corrections_max_m, voxel_size_m)) {
    char why[160];
    std::snprintf(why, sizeof why,
                  "levelled by gravity, no scan moved more than a quarter voxel (%.1f mm): the "
                  "map stays",
                  1000.0 * loops->corrections_max_m);
    return {SecondPass::kLevelledInPlace, why};
  }
  if (interrupted)
    return {SecondPass::kInterrupted, "interrupted: the map keeps the odometry's poses"};
  if (!integrate) return {SecondPass::kPosesOnly, "--poses-only: no map"};
  if (!replayable) {
    return {SecondPass::kNotReplayable,
            "the input cannot be read twice: the map keeps the odometry's poses"};
  }
  return {SecondPass::kMapAgain, "mapping the recording again with the corrected poses"};
}

EarlierSessionsOutcome plan_earlier_sessions(double moved_m, double voxel_size_m,
                                             const std::string& why_unreadable) {
  if (!moves_the_map(moved_m, voxel_size_m))
    return {EarlierSessions::kUnmoved, "no keyframe moved more than a quarter voxel"};
  if (!why_unreadable.empty())
    return {EarlierSessions::kKept, why_unreadable + ": the earlier map stays as it was"};
  return {EarlierSessions::kMappedAgain, ""};
}

}  // namespace featsense::mapping
