#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include "common/test_data.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "trajectory_test_paths.hpp"

namespace featsense::test {
namespace {

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const slam::TrajectoryError& e) {
    return e.what();
  }
  return "";
}

TEST(TrajectoryIo, TumRoundTripKeepsStampsAndPoses) {
  const auto dir = scratch_dir("traj_io_tum");
  const slam::Trajectory original = helix_trajectory(50, 1'700'000'000'123'456'789);
  slam::write_tum(original, (dir / "t.tum").string());
  const slam::Trajectory read = slam::read_tum((dir / "t.tum").string());
  ASSERT_EQ(read.size(), original.size());
  EXPECT_TRUE(read.has_stamps);
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read.stamps_ns[i], original.stamps_ns[i]);
    EXPECT_TRUE(read.poses[i].isApprox(original.poses[i], 1e-8)) << i;
  }
}

TEST(TrajectoryIo, TumValuesAreStampPositionQuaternion) {
  const auto dir = scratch_dir("traj_io_tum_values");
  // A quarter turn about z: q = (w, x, y, z) = (cos 45, 0, 0, sin 45).
  write_text(dir / "t.tum", "# comment\n\n2.5 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n");
  const slam::Trajectory t = slam::read_tum((dir / "t.tum").string());
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t.stamps_ns[0], 2'500'000'000);
  EXPECT_TRUE(t.poses[0].translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE((t.poses[0].linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
}

TEST(TrajectoryIo, KittiRoundTripAndTimesFile) {
  const auto dir = scratch_dir("traj_io_kitti");
  const slam::Trajectory original = helix_trajectory(20);
  slam::write_kitti(original, (dir / "poses.txt").string());
  const slam::Trajectory read = slam::read_kitti((dir / "poses.txt").string());
  ASSERT_EQ(read.size(), 20u);
  EXPECT_FALSE(read.has_stamps);
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_TRUE(read.poses[i].isApprox(original.poses[i], 1e-8)) << i;
  }
  std::string times;
  for (int i = 0; i < 20; ++i) times += std::to_string(0.1 * i) + "\n";
  write_text(dir / "times.txt", times);
  const slam::Trajectory timed =
      slam::read_kitti((dir / "poses.txt").string(), (dir / "times.txt").string());
  EXPECT_TRUE(timed.has_stamps);
  EXPECT_EQ(timed.stamps_ns[19], 1'900'000'000);
  write_text(dir / "short.txt", "0\n0.1\n");
  EXPECT_NE(error_of([&] {
              slam::read_kitti((dir / "poses.txt").string(), (dir / "short.txt").string());
            }).find("2 times for 20 poses"),
            std::string::npos);
}

TEST(TrajectoryIo, ErrorsNameFileAndLine) {
  const auto dir = scratch_dir("traj_io_errors");
  const std::string bad = (dir / "bad.tum").string();
  write_text(dir / "bad.tum", "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n");
  EXPECT_NE(error_of([&] { slam::read_tum(bad); }).find(bad + ":2: expected 8 numbers"),
            std::string::npos);
  write_text(dir / "bad.tum", "1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  EXPECT_NE(error_of([&] { slam::read_tum(bad); }).find(":2: time stamps must increase"),
            std::string::npos);
  write_text(dir / "bad.tum", "1 0 0 0 0 0 0 2\n");
  EXPECT_NE(error_of([&] { slam::read_tum(bad); }).find(":1: quaternion"), std::string::npos);
  write_text(dir / "bad.tum", "# only a comment\n");
  EXPECT_NE(error_of([&] { slam::read_tum(bad); }).find("no pose"), std::string::npos);
  EXPECT_NE(error_of([&] { slam::read_tum((dir / "missing.tum").string()); }).find("cannot open"),
            std::string::npos);
  write_text(dir / "bad.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(error_of([&] {
              slam::read_kitti((dir / "bad.kitti").string());
            }).find("bad.kitti:2: the 3 x 3 part is not a rotation"),
            std::string::npos);
}

TEST(TrajectoryIo, TheFormatIsDetectedFromTheContent) {
  const auto dir = scratch_dir("traj_io_detect");
  const slam::Trajectory original = helix_trajectory(5, 1'700'000'000'000'000'000);
  slam::write_tum(original, (dir / "poses.txt").string());
  slam::write_kitti(original, (dir / "poses_kitti.txt").string());
  EXPECT_EQ(slam::detect_trajectory_format((dir / "poses.txt").string()), "tum");
  EXPECT_EQ(slam::detect_trajectory_format((dir / "poses_kitti.txt").string()), "kitti");
  const slam::Trajectory tum = slam::read_trajectory((dir / "poses.txt").string());
  EXPECT_TRUE(tum.has_stamps);
  EXPECT_EQ(tum.size(), 5u);
  const slam::Trajectory kitti = slam::read_trajectory((dir / "poses_kitti.txt").string());
  EXPECT_FALSE(kitti.has_stamps);
  EXPECT_EQ(kitti.size(), 5u);

  write_text(dir / "odd.txt", "# comment\n\n1 2 3 4 5\n");
  EXPECT_NE(error_of([&] {
              slam::read_trajectory((dir / "odd.txt").string());
            }).find("neither TUM (8) nor KITTI (12)"),
            std::string::npos);
  write_text(dir / "empty.txt", "# nothing\n");
  EXPECT_NE(error_of([&] {
              slam::detect_trajectory_format((dir / "empty.txt").string());
            }).find("holds no pose"),
            std::string::npos);
  // A times file belongs to KITTI poses; TUM lines carry their own stamps.
  write_text(dir / "times.txt", "0\n0.1\n0.2\n0.3\n0.4\n");
  EXPECT_NE(error_of([&] {
              slam::read_trajectory((dir / "poses.txt").string(), "auto",
                                    (dir / "times.txt").string());
            }).find("goes with KITTI poses"),
            std::string::npos);
  const slam::Trajectory timed = slam::read_trajectory((dir / "poses_kitti.txt").string(), "auto",
                                                       (dir / "times.txt").string());
  EXPECT_TRUE(timed.has_stamps);
}

TEST(TrajectoryIo, ReadsTheSharedKittiPoses) {
  FEATSENSE_SHARED_FILE(path, "ouster/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt");
  const slam::Trajectory t = slam::read_kitti(path.string());
  ASSERT_EQ(t.size(), 3u);  // one pose per frame of the recording
  EXPECT_FALSE(t.has_stamps);
  // The sensor moves about 0.25 m per frame (../shared/data/README.md).
  const double step = (t.poses[1].translation() - t.poses[0].translation()).norm();
  EXPECT_GT(step, 0.1);
  EXPECT_LT(step, 0.5);
}

}  // namespace
}  // namespace featsense::test
