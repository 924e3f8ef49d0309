// The decisions after a first pass, each with its reason: a second pass only where the
// corrected poses change the map, and the earlier sessions of a saved map mapped again only
// where they moved and can be read again.

#include <gtest/gtest.h>

#include "featsense/mapping/map_policy.hpp"

namespace featsense::mapping {
namespace {

constexpr double kVoxel = 0.064;  // a quarter voxel: 16 mm

LoopOutcome levelled_by(double corrections_max_m) {
  LoopOutcome loops;
  loops.gravity.observations = 12;
  loops.corrections_max_m = corrections_max_m;
  return loops;
}

TEST(MapPolicy, AQuarterVoxelIsTheLineBetweenAMapThatStaysAndOneMadeAgain) {
  EXPECT_FALSE(moves_the_map(0.015, kVoxel));
  EXPECT_FALSE(moves_the_map(0.016, kVoxel));
  EXPECT_TRUE(moves_the_map(0.0161, kVoxel));
}

TEST(MapPolicy, NoLoopClosureNoSecondPass) {
  EXPECT_EQ(plan_second_pass(nullptr, false, true, true, kVoxel).kind, SecondPass::kNotNeeded);
  const LoopOutcome nothing;
  EXPECT_EQ(plan_second_pass(&nothing, false, true, true, kVoxel).kind, SecondPass::kNotNeeded);
}

TEST(MapPolicy, LevellingThatMovesNoScanAQuarterVoxelKeepsTheMap) {
  const LoopOutcome small = levelled_by(0.004);
  const SecondPassOutcome kept = plan_second_pass(&small, false, true, true, kVoxel);
  EXPECT_EQ(kept.kind, SecondPass::kLevelledInPlace);
  EXPECT_NE(kept.reason.find("4.0 mm"), std::string::npos) << kept.reason;
  const LoopOutcome large = levelled_by(0.05);
  EXPECT_EQ(plan_second_pass(&large, false, true, true, kVoxel).kind, SecondPass::kMapAgain);
}

TEST(MapPolicy, ALoopClosedMapsAgainUnlessStoppedUnmappedOrUnreadable) {
  LoopOutcome loops;
  loops.loops.emplace_back();
  EXPECT_EQ(plan_second_pass(&loops, false, true, true, kVoxel).kind, SecondPass::kMapAgain);
  EXPECT_EQ(plan_second_pass(&loops, true, true, true, kVoxel).kind, SecondPass::kInterrupted);
  EXPECT_EQ(plan_second_pass(&loops, false, false, true, kVoxel).kind, SecondPass::kPosesOnly);
  EXPECT_EQ(plan_second_pass(&loops, false, true, false, kVoxel).kind, SecondPass::kNotReplayable);
}

TEST(MapPolicy, EarlierSessionsAreMappedAgainOnlyWhereTheyMovedAndCanBeRead) {
  EXPECT_EQ(plan_earlier_sessions(0.01, kVoxel, "").kind, EarlierSessions::kUnmoved);
  EXPECT_EQ(plan_earlier_sessions(0.10, kVoxel, "").kind, EarlierSessions::kMappedAgain);
  const EarlierSessionsOutcome kept =
      plan_earlier_sessions(0.10, kVoxel, "session 0's input /gone.pcap is gone");
  EXPECT_EQ(kept.kind, EarlierSessions::kKept);
  EXPECT_EQ(kept.reason, "session 0's input /gone.pcap is gone: the earlier map stays as it was");
}

}  // namespace
}  // namespace featsense::mapping
