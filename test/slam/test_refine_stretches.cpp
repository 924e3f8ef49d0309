#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <optional>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/io/box_room_source.hpp"
#include "featsense/slam/refine/placement_refiner.hpp"
#include "featsense/slam/refine/segment_refiner.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "scene_sampling.hpp"

namespace featsense::slam::refine {
namespace {

using test::pose;

double degrees(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return test::angle_between(a, b) * 180.0 / M_PI;
}

/// A sensor walking 14 m along the lab's south side, a scan every 0.2 m: its true poses, and
/// an odometry that drifts as odometry does, more the farther it goes (1 cm sideways, 0.5 cm
/// down and 0.05 deg of yaw per metre).
struct DriftingWalk {
  std::vector<Eigen::Isometry3d> truth;
  std::vector<ScanPlacement> placed_in;
  std::vector<Eigen::Isometry3d> odometry;

  DriftingWalk() {
    for (int i = 0; i < 71; ++i) {
      const double walked = 0.2 * i;
      truth.push_back(pose(0.3, 0.0, 0.0, {-7.0 + walked, -7.5, 1.5}));
      const Eigen::Isometry3d drift =
          pose(0.05 * M_PI / 180.0 * walked, 0.0, 0.0, {0.0, 0.01 * walked, -0.005 * walked});
      // The drift turns about the first scan's place, where the map starts.
      odometry.push_back(truth.front() * drift * truth.front().inverse() * truth[i]);
    }
  }
};

/// What the sensor at `T_map_sensor` sees of the lab, as a cloud in its own frame: a noisy
/// sampling of the whole room (1 cm per axis), new for each scan.
GaussianCloud lab_cloud(const mesh::TriangleMesh& lab, const Eigen::Isometry3d& T_map_sensor,
                        uint32_t seed) {
  std::vector<Eigen::Vector3f> points =
      test::sample_scene(lab, {0.0f, 0.0f, 2.0f}, 30.0f, 8000, 0.01f, seed);
  for (Eigen::Vector3f& p : points) p = (T_map_sensor.inverse() * p.cast<double>()).cast<float>();
  return with_covariances(points, 10);
}

/// Runs the walk through a refiner: the final pose of every scan, in order.
std::vector<Eigen::Isometry3d> refine_walk(const DriftingWalk& walk, SegmentRefiner& refiner) {
  const mesh::TriangleMesh lab = build_scene("lab");
  std::vector<Eigen::Isometry3d> final;
  for (size_t i = 0; i < walk.truth.size(); ++i) {
    GaussianCloud cloud;
    if (refiner.needs_cloud(walk.odometry[i]))
      cloud = lab_cloud(lab, walk.truth[i], static_cast<uint32_t>(i + 1));
    if (refiner.add(walk.odometry[i], std::move(cloud))) {
      for (const Eigen::Isometry3d& p : refiner.refine()) final.push_back(p);
    }
  }
  for (const Eigen::Isometry3d& p : refiner.refine()) final.push_back(p);
  return final;
}

RefineSettings every_two_metres() {
  RefineSettings settings;
  settings.distance_m = 2.0;
  settings.voxel_m = 0.25;
  settings.vgicp.voxel_sizes_m = {0.5, 0.25};
  return settings;
}

TEST(SegmentRefiner, TheOdometrysDriftIsNotHandedOn) {
  const DriftingWalk walk;
  SegmentRefiner refiner(every_two_metres());
  const std::vector<Eigen::Isometry3d> final = refine_walk(walk, refiner);
  ASSERT_EQ(final.size(), walk.truth.size());
  // The first scan fixes the frame: its pose stays.
  EXPECT_TRUE(final.front().isApprox(walk.odometry.front(), 1e-12));
  const double odometry_m =
      (walk.odometry.back().translation() - walk.truth.back().translation()).norm();
  ASSERT_GT(odometry_m, 0.15);
  double worst_m = 0.0, worst_deg = 0.0;
  for (size_t i = 0; i < final.size(); ++i) {
    ASSERT_TRUE(final[i].matrix().allFinite()) << i;
    worst_m = std::max(worst_m, (final[i].translation() - walk.truth[i].translation()).norm());
    worst_deg = std::max(worst_deg, degrees(final[i], walk.truth[i]));
  }
  RecordProperty("odometry_end_error_m", std::to_string(odometry_m));
  RecordProperty("refined_worst_error_m", std::to_string(worst_m));
  RecordProperty("refined_worst_error_deg", std::to_string(worst_deg));
  // 14 m of 1 cm noise, registered stretch by stretch: within a centimetre all along.
  EXPECT_LT(worst_m, 0.015);
  EXPECT_LT(worst_deg, 0.1);
  const RefineCounts& counts = refiner.counts();
  EXPECT_EQ(counts.scans, walk.truth.size());
  EXPECT_GE(counts.refined, 6u);
  EXPECT_EQ(counts.not_converged + counts.too_far + counts.worse_fit, 0u);
}

TEST(SegmentRefiner, ARejectedRegistrationKeepsTheOdometrysMotion) {
  const DriftingWalk walk;
  RefineSettings settings = every_two_metres();
  settings.max_correction_m = 1e-4;  // every correction is "too far"
  SegmentRefiner refiner(settings);
  const std::vector<Eigen::Isometry3d> final = refine_walk(walk, refiner);
  ASSERT_EQ(final.size(), walk.odometry.size());
  for (size_t i = 0; i < final.size(); ++i)
    EXPECT_TRUE(final[i].isApprox(walk.odometry[i], 1e-9)) << i;
  const RefineCounts& counts = refiner.counts();
  EXPECT_EQ(counts.refined, 0u);
  EXPECT_GE(counts.too_far, 6u);
  for (const StretchRegistration& stretch : counts.stretches) {
    if (stretch.outcome == RefineOutcome::too_far) {
      EXPECT_GT(stretch.step_m, 1e-4);
    }
  }
}

TEST(SegmentRefiner, AStandingSensorEndsAStretchByCount) {
  RefineSettings settings = every_two_metres();
  settings.max_scans = 5;
  SegmentRefiner refiner(settings);
  EXPECT_TRUE(refiner.add(Eigen::Isometry3d::Identity(), {}));  // the first scan, alone
  EXPECT_EQ(refiner.refine().size(), 1u);
  for (int i = 1; i < 5; ++i) EXPECT_FALSE(refiner.add(Eigen::Isometry3d::Identity(), {})) << i;
  EXPECT_TRUE(refiner.needs_cloud(Eigen::Isometry3d::Identity())) << "the stretch's last scan";
  EXPECT_TRUE(refiner.add(Eigen::Isometry3d::Identity(), {}));
  const std::vector<Eigen::Isometry3d> final = refiner.refine();
  ASSERT_EQ(final.size(), 5u);
  for (const Eigen::Isometry3d& p : final) EXPECT_TRUE(p.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(SegmentRefiner, AStretchTheSensorStoodThroughIsNotMoved) {
  // The odometry held the pose (standing still): a registration of the stand against the
  // stretch before would move it by its noise, a drift of its own.
  const mesh::TriangleMesh lab = build_scene("lab");
  RefineSettings settings = every_two_metres();
  settings.max_scans = 6;
  SegmentRefiner refiner(settings);
  const Eigen::Isometry3d stand = pose(0.3, 0.0, 0.0, {-7.0, -7.5, 1.5});
  ASSERT_TRUE(refiner.add(stand, lab_cloud(lab, stand, 1)));
  ASSERT_EQ(refiner.refine().size(), 1u);
  for (uint32_t round = 0; round < 3; ++round) {
    for (uint32_t i = 0; i < 6; ++i) {
      GaussianCloud cloud;
      if (refiner.needs_cloud(stand)) cloud = lab_cloud(lab, stand, 10 * round + i + 2);
      if (!refiner.add(stand, std::move(cloud))) continue;
      for (const Eigen::Isometry3d& p : refiner.refine()) {
        EXPECT_TRUE(p.isApprox(stand, 1e-12)) << "round " << round;
      }
    }
  }
  EXPECT_EQ(refiner.counts().stood, 3u);
  EXPECT_EQ(refiner.counts().refined, 0u);
}

/// The box room's scans placed with their true poses (the map frame at the first), deskewed
/// with the true motion except the first, placed before any motion is known.
TEST(PlacementRefiner, FinalPlacementsComeInOrderAndTheFirstIsDeskewed) {
  BoxRoomSettings room = default_box_room();
  room.frames = 8;
  const Eigen::Isometry3d T_first = box_room_pose(room, 0.0);
  auto source = make_box_room_source(room);
  RefineSettings settings;
  settings.distance_m = 100.0;  // one stretch: all held until finish()
  PlacementRefiner refiner(settings);
  std::vector<ScanPlacement> out;
  std::vector<Eigen::Isometry3d> truth;
  std::vector<ScanPlacement> placed_in;
  int64_t first_stamp = 0;
  for (uint64_t i = 0; std::optional<Scan> scan = source->next(); ++i) {
    if (i == 0) first_stamp = scan->stamp_ns;
    const auto at = [&](double seconds_after_stamp) {
      const double t =
          static_cast<double>(scan->stamp_ns - first_stamp) * 1e-9 + seconds_after_stamp;
      return T_first.inverse() * box_room_pose(room, t);
    };
    ScanPlacement placed;
    placed.sequence = i;
    placed.stamp_ns = scan->stamp_ns;
    placed.T_map_sensor = at(0.0);
    truth.push_back(placed.T_map_sensor);
    if (i > 0) {
      placed.column_T_map_sensor = column_poses(*scan, placed.T_map_sensor, [&](double t) {
        return std::optional<Eigen::Isometry3d>(at(t));
      });
    }
    placed_in.push_back(placed);
    for (ScanPlacement& p : refiner.add(*scan, placed)) out.push_back(std::move(p));
    if (i == 0) {
      EXPECT_TRUE(out.empty()) << "the first waits for the motion";
    }
    if (i == 1) {
      ASSERT_EQ(out.size(), 1u) << "the first scan is a stretch of its own";
      // Deskewed with the motion to the second scan: the room's own (1 m/s, straight).
      ASSERT_EQ(out[0].column_T_map_sensor.size(), static_cast<size_t>(scan->cols));
      for (const Eigen::Isometry3d& column : out[0].column_T_map_sensor)
        EXPECT_LT(column.translation().norm(), 0.1 + 1e-9);
      EXPECT_GT(out[0].column_T_map_sensor.back().translation().x(), 0.09);
    }
  }
  for (ScanPlacement& p : refiner.finish()) out.push_back(std::move(p));
  ASSERT_EQ(out.size(), 8u);
  for (uint64_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].sequence, i);
    // True poses stay true, and each column moves with its scan's pose.
    EXPECT_LT((out[i].T_map_sensor.translation() - truth[i].translation()).norm(), 0.01) << i;
    ASSERT_FALSE(out[i].column_T_map_sensor.empty()) << i;
    if (i == 0) continue;  // its motion was the refiner's own (checked above)
    const Eigen::Isometry3d correction = out[i].T_map_sensor * placed_in[i].T_map_sensor.inverse();
    for (const size_t c : {size_t{0}, out[i].column_T_map_sensor.size() - 1}) {
      EXPECT_TRUE(out[i].column_T_map_sensor[c].isApprox(
          correction * placed_in[i].column_T_map_sensor[c], 1e-9))
          << i << " column " << c;
    }
  }
  EXPECT_EQ(refiner.counts().scans, 8u);
}

}  // namespace
}  // namespace featsense::slam::refine
