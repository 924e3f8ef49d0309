// The search for a scan's place near a guess: a street whose facades have doors and posts at
// irregular places, a scan from a true pose, and guesses metres along the street, turned a
// few degrees or facing the other way, as a place descriptor gives them.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "place_correlation.hpp"

namespace featsense::mapping {
namespace {

/// Facades at y = +-6 m from x = -120 to 120 m, broken by doors 1.5 m wide at irregular
/// places, and posts along the kerbs: upright points every 0.25 m, at heights 0.5 .. 4 m.
std::vector<Eigen::Vector3d> street() {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> spacing(4.0, 14.0);
  std::vector<double> doors;
  for (double x = -120.0; x < 120.0; x += spacing(random)) doors.push_back(x);
  std::vector<Eigen::Vector3d> points;
  for (double x = -120.0; x <= 120.0; x += 0.25) {
    bool door = false;
    for (double d : doors) door = door || (x >= d && x < d + 1.5);
    if (door) continue;
    for (double z = 0.5; z <= 4.0; z += 0.5) {
      points.emplace_back(x, 6.0, z);
      points.emplace_back(x, -6.0, z);
    }
  }
  for (double x = -118.0; x < 120.0; x += spacing(random))
    for (double z = 0.5; z <= 2.5; z += 0.5) points.emplace_back(x, (x > 0 ? 4.5 : -4.5), z);
  return points;
}

std::vector<Eigen::Vector2f> from_above(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector2f> out;
  for (const Eigen::Vector3d& p : points) out.push_back(p.head<2>().cast<float>());
  return out;
}

/// What a sensor at `T_map_sensor` sees of `points` within 40 m, in its own frame.
std::vector<Eigen::Vector3d> seen_from(const std::vector<Eigen::Vector3d>& points,
                                       const Eigen::Isometry3d& T_map_sensor) {
  std::vector<Eigen::Vector3d> out;
  const Eigen::Isometry3d T_sensor_map = T_map_sensor.inverse();
  for (const Eigen::Vector3d& p : points)
    if ((p - T_map_sensor.translation()).head<2>().norm() <= 40.0) out.push_back(T_sensor_map * p);
  return out;
}

Eigen::Isometry3d pose(double x, double y, double z, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

double yaw_deg_between(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Matrix3d R = a.linear().transpose() * b.linear();
  return std::atan2(R(1, 0), R(0, 0)) * 180.0 / M_PI;
}

TEST(PlaceCorrelation, FindsTheScanFifteenMetresAlongTheStreetFromTheGuess) {
  const std::vector<Eigen::Vector3d> map = street();
  const Eigen::Isometry3d truth = pose(12.3, -0.7, 1.8, 3.0);
  const std::vector<Eigen::Vector3d> scan = seen_from(map, truth);
  // The descriptor's keyframe lies 15 m on, its heading 3 degrees off, its height the car's.
  const Eigen::Isometry3d guess = pose(27.3, 0.4, 2.2, 0.0);
  const std::vector<PlacePeak> peaks = correlate_place(from_above(map), {}, scan, guess, {});
  ASSERT_FALSE(peaks.empty());
  EXPECT_LT((peaks.front().T_map_query.translation() - truth.translation()).head<2>().norm(), 0.3);
  EXPECT_LT(std::abs(yaw_deg_between(peaks.front().T_map_query, truth)), 0.6);
  EXPECT_GT(peaks.front().score, 0.9);
  // The height is the guess's: heights are not compared.
  EXPECT_DOUBLE_EQ(peaks.front().T_map_query.translation().z(), 2.2);
  // The runner-up is another place, or the same facing the other way, and fits worse.
  ASSERT_EQ(peaks.size(), 2u);
  EXPECT_TRUE((peaks[1].T_map_query.translation() - peaks[0].T_map_query.translation()).norm() >=
                  4.0 ||
              std::abs(yaw_deg_between(peaks[1].T_map_query, peaks[0].T_map_query)) > 90.0);
  EXPECT_LT(peaks[1].score, peaks[0].score);
}

TEST(PlaceCorrelation, FindsASensorFacingTheOtherWayThanTheGuess) {
  const std::vector<Eigen::Vector3d> map = street();
  const Eigen::Isometry3d truth = pose(-40.0, 1.0, 1.8, 181.0);
  const std::vector<Eigen::Vector3d> scan = seen_from(map, truth);
  const Eigen::Isometry3d guess = pose(-31.0, 0.0, 1.8, 0.0);
  const std::vector<PlacePeak> peaks = correlate_place(from_above(map), {}, scan, guess, {});
  ASSERT_FALSE(peaks.empty());
  EXPECT_LT((peaks.front().T_map_query.translation() - truth.translation()).head<2>().norm(), 0.3);
  EXPECT_LT(std::abs(yaw_deg_between(peaks.front().T_map_query, truth)), 0.6);

  PlaceCorrelationSettings one_way;
  one_way.both_ways = false;
  const std::vector<PlacePeak> facing = correlate_place(from_above(map), {}, scan, guess, one_way);
  ASSERT_FALSE(facing.empty());
  EXPECT_LT(facing.front().score, peaks.front().score);
}

TEST(PlaceCorrelation, StaysWithinReach) {
  const std::vector<Eigen::Vector3d> map = street();
  const Eigen::Isometry3d truth = pose(0.0, 0.0, 1.8, 0.0);
  const std::vector<Eigen::Vector3d> scan = seen_from(map, truth);
  PlaceCorrelationSettings settings;
  settings.reach_m = 5.0;
  const std::vector<PlacePeak> peaks =
      correlate_place(from_above(map), {}, scan, pose(30.0, 0.0, 1.8, 0.0), settings);
  ASSERT_FALSE(peaks.empty());
  for (const PlacePeak& peak : peaks)
    EXPECT_LE((peak.T_map_query.translation() - Eigen::Vector3d(30.0, 0.0, 1.8)).norm(),
              5.0 * std::sqrt(2.0) + 1e-9);
}

TEST(PlaceCorrelation, AScanWithoutUprightSurfaceGivesNoPlace) {
  const std::vector<Eigen::Vector3d> map = street();
  EXPECT_TRUE(correlate_place(from_above(map), {}, {}, pose(0, 0, 0, 0), {}).empty());
  // Points beyond the range compared only.
  EXPECT_TRUE(
      correlate_place(from_above(map), {}, {Eigen::Vector3d(50.0, 0.0, 1.0)}, pose(0, 0, 0, 0), {})
          .empty());
  // An empty map: every shift scores nothing, and the guess itself comes first.
  const std::vector<PlacePeak> none =
      correlate_place({}, {}, {Eigen::Vector3d(5.0, 0.0, 1.0)}, pose(1, 2, 3, 0), {});
  ASSERT_FALSE(none.empty());
  EXPECT_EQ(none.front().score, 0.0);
  EXPECT_TRUE(none.front().T_map_query.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(PlaceCorrelation, UprightPointsAreThoseWhoseSurfaceStandsInTheMapFrame) {
  slam::refine::GaussianCloud cloud;
  cloud.points = {Eigen::Vector3d(1, 0, -1.8), Eigen::Vector3d(5, 0, 0)};
  // A floor (thin along z) and a wall (thin along x).
  cloud.covariances = {Eigen::Vector3d(1, 1, 1e-3).asDiagonal(),
                       Eigen::Vector3d(1e-3, 1, 1).asDiagonal()};
  const std::vector<Eigen::Vector3d> level =
      upright_points(cloud, Eigen::Matrix3d::Identity(), 0.5);
  ASSERT_EQ(level.size(), 1u);
  EXPECT_TRUE(level.front().isApprox(Eigen::Vector3d(5, 0, 0)));
  // A sensor pitched 90 degrees sees the floor as a wall and the wall as a ceiling.
  const Eigen::Matrix3d pitched =
      Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const std::vector<Eigen::Vector3d> turned = upright_points(cloud, pitched, 0.5);
  ASSERT_EQ(turned.size(), 1u);
  EXPECT_TRUE(turned.front().isApprox(Eigen::Vector3d(1, 0, -1.8)));
}

}  // namespace
}  // namespace featsense::mapping
