#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "featsense/slam/refine/vgicp.hpp"
#include "map_path.hpp"
#include "map_targets.hpp"

namespace featsense::mapping {
namespace {

constexpr double kDegree = M_PI / 180.0;

TEST(SurfaceSigma, GrowsWithRangeWhereTheSurfaceIsSeenObliquelyAndVanishesFaceOn) {
  const Eigen::Vector3d from(0.0, 0.0, 2.0);
  const double angle = 0.05 * kDegree;
  // Ground 30 m away, seen at a grazing angle: across the line of sight is almost up.
  EXPECT_NEAR(surface_sigma({30.0, 0.0, 0.0}, Eigen::Vector3d::UnitZ(), from, angle), angle * 30.0,
              1e-12);
  // A wall faced squarely: its error moves it along itself, not along its normal.
  EXPECT_NEAR(surface_sigma({30.0, 0.0, 2.0}, Eigen::Vector3d::UnitX(), from, angle), 0.0, 1e-12);
  // The same wall seen at 45 degrees, 28.3 m off: the range times sin 45 degrees.
  EXPECT_NEAR(surface_sigma({20.0, 20.0, 2.0}, Eigen::Vector3d::UnitX(), from, angle), angle * 20.0,
              1e-12);
}

TEST(MapPath, KeepsOnePositionPerSpacingAndFallsBackToTheKeyframes) {
  SavedMap saved;
  SavedSession session;
  for (int i = 0; i <= 100; ++i)
    session.poses.push_back(i, Eigen::Isometry3d(Eigen::Translation3d(0.1 * i, 0.0, 1.0)));
  saved.sessions.push_back(session);
  const MapPath path(saved, 2.0);
  ASSERT_EQ(path.positions().size(), 6u);  // 0, 2, 4, 6, 8, 10 m
  EXPECT_NEAR(path.positions().back().x(), 10.0, 1e-9);

  SavedMap old;  // no trajectory split into sessions: its keyframes
  for (int i = 0; i < 3; ++i) {
    slam::loops::MapKeyframe keyframe;
    keyframe.T_map_sensor = Eigen::Translation3d(5.0 * i, 1.0, 0.0) * Eigen::Isometry3d::Identity();
    old.keyframes.push_back(keyframe);
  }
  EXPECT_EQ(MapPath(old, 2.0).positions().size(), 3u);
}

TEST(SeenFrom, EachCellKnowsThePathsNearestPositionAsABruteForceSearchFindsIt) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> across(-80.0, 80.0);
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i < 200; ++i) positions.emplace_back(across(random), across(random), 1.5);
  const MapPath path(positions);
  const Eigen::Vector3d centre(10.0, -5.0, 0.0);
  const SeenFrom seen(path, centre, 40.0, 1.0, 60.0);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d p =
        centre + Eigen::Vector3d(0.5 * across(random), 0.5 * across(random), 0.0);
    const Eigen::Vector3f* nearest = seen.nearest(p);
    ASSERT_NE(nearest, nullptr);
    // To the cell's centre: within the cell's half diagonal of the nearest to the point.
    double best = 1e9;
    for (const Eigen::Vector3d& q : positions) best = std::min(best, (q - p).head<2>().norm());
    EXPECT_LE((nearest->cast<double>() - p).head<2>().norm(), best + std::sqrt(0.5) * 2.0 + 1e-6);
  }
  EXPECT_EQ(seen.nearest(centre + Eigen::Vector3d(41.0, 0.0, 0.0)), nullptr);
  EXPECT_EQ(
      SeenFrom(MapPath(std::vector<Eigen::Vector3d>{{500.0, 0.0, 0.0}}), centre, 40.0, 1.0, 60.0)
          .nearest(centre),
      nullptr);
}

/// A street: flat ground, a wall along it and a wall across it at each end, its surface cells
/// 0.25 m apart, the map's path along y = 0. Each cell is moved along its normal by `move`.
std::vector<slam::refine::VoxelGaussian> street(
    const std::function<double(const Eigen::Vector3d&, const Eigen::Vector3d&)>& move) {
  std::vector<slam::refine::VoxelGaussian> parts;
  const auto add = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
    slam::refine::VoxelGaussian part;
    part.mean = p + move(p, n) * n;
    part.covariance = Eigen::Matrix3d::Identity() - (1.0 - 1e-3) * n * n.transpose();
    part.normal = n;
    part.points = 1;
    parts.push_back(part);
  };
  for (double x = -29.875; x < 30.0; x += 0.25)
    for (double y = -9.875; y < 60.0; y += 0.25) add({x, y, 0.0}, Eigen::Vector3d::UnitZ());
  for (double y = -9.875; y < 60.0; y += 0.25)
    for (double z = 0.125; z < 4.0; z += 0.25) add({8.0, y, z}, -Eigen::Vector3d::UnitX());
  for (double x = -29.875; x < 8.0; x += 0.25) {
    for (double z = 0.125; z < 4.0; z += 0.25) {
      add({x, 55.0, z}, -Eigen::Vector3d::UnitY());
      add({x, -8.0, z}, Eigen::Vector3d::UnitY());
    }
  }
  return parts;
}

MapTarget target_of(const std::vector<slam::refine::VoxelGaussian>& parts, const MapPath& path,
                    const Eigen::Vector3d& centre) {
  std::vector<slam::refine::VoxelGaussians> levels;
  for (const double voxel : {1.0, 0.5, 0.25}) levels.emplace_back(parts, voxel);
  MapTarget target(centre, slam::refine::VgicpTarget(std::move(levels),
                                                     slam::refine::VoxelGaussians(parts, 0.5)));
  target.block_m = 0.5;
  for (const slam::refine::VoxelGaussian& part : parts)
    target.observed.insert(grid_key(grid_index(part.mean, 0.5)));
  target.seen_from.emplace(path, centre, 60.0, 1.0, 60.0);
  return target;
}

/// The street's surface within 20 m of `sensor`, 0.5 m apart, in the sensor's frame.
slam::refine::GaussianCloud scan_at(const Eigen::Vector3d& sensor) {
  slam::refine::GaussianCloud cloud;
  for (const slam::refine::VoxelGaussian& part : street([](auto&, auto&) { return 0.0; })) {
    const Eigen::Vector3d p = part.mean;
    if ((p - sensor).head<2>().norm() > 20.0) continue;
    if (std::fmod(std::abs(p.x() + p.y() + p.z()), 0.5) > 0.26) continue;  // every other cell
    cloud.points.push_back(p - sensor);
    cloud.covariances.push_back(part.covariance);
  }
  return cloud;
}

TEST(MapFitSurface, ThePoseIsWorthWhatTheSurfacesItStandsOnWereSeenFrom) {
  std::vector<Eigen::Vector3d> positions;
  for (double x = -40.0; x <= 40.0; x += 2.0) positions.emplace_back(x, 0.0, 2.0);
  const MapPath path(positions);
  const double angle = 0.05 * kDegree;
  const auto flat = [](const Eigen::Vector3d&, const Eigen::Vector3d&) { return 0.0; };
  const Eigen::Vector3d near_path(0.0, 3.0, 2.0), far_off(0.0, 38.0, 2.0);

  const auto fit_at = [&](const Eigen::Vector3d& sensor, double angle_rad) {
    const MapTarget target = target_of(street(flat), path, sensor);
    return measure_map_fit(target, scan_at(sensor), Eigen::Isometry3d(Eigen::Translation3d(sensor)),
                           0.2, angle_rad);
  };
  const MapFit near_fit = fit_at(near_path, angle);
  const MapFit far_fit = fit_at(far_off, angle);
  ASSERT_TRUE(std::isfinite(near_fit.position_sigma_m));
  ASSERT_TRUE(std::isfinite(far_fit.position_sigma_m));
  // The ground under the far sensor was seen from 18-58 m; under the near one from 0-23 m.
  EXPECT_GT(far_fit.surface_position_m, 3.0 * near_fit.surface_position_m);
  EXPECT_GT(far_fit.surface_position_m, angle * 30.0);
  EXPECT_EQ(fit_at(far_off, 0.0).surface_position_m, 0.0);
  EXPECT_NEAR(fit_at(far_off, 2.0 * angle).surface_position_m, 2.0 * far_fit.surface_position_m,
              1e-9);

  // Such an error made real: every surface moved along its normal by its sigma (the ground
  // raised in proportion to its distance from the path, a tilted ground; the walls pushed
  // out). Registered to that map from the truth, the far sensor's pose moves by no more than
  // the bound, and by a good part of it (the ground's height at the sensor: 0.05 deg times
  // 38 m, 33 mm, against a bound of 48 mm; 10 mm near the path).
  const auto seen_error = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
    return surface_sigma(p, n, Eigen::Vector3d(std::round(p.x() / 2.0) * 2.0, 0.0, 2.0), angle);
  };
  const MapTarget moved = target_of(street(seen_error), path, far_off);
  slam::refine::VgicpSettings settings;
  settings.voxel_sizes_m = {1.0, 0.5, 0.25};
  settings.max_iterations = 30;
  const Eigen::Isometry3d truth = Eigen::Translation3d(far_off) * Eigen::Isometry3d::Identity();
  const slam::refine::VgicpResult result =
      slam::refine::align(moved.vgicp, scan_at(far_off), truth, settings);
  const double shift = (result.T_target_source.translation() - far_off).norm();
  EXPECT_LE(shift, far_fit.surface_position_m);
  EXPECT_GT(shift, 0.5 * far_fit.surface_position_m);
}

TEST(MapFitUpright, TheGroundFitsAnywhereWhatStandsOnItTellsThePlace) {
  const MapPath path(std::vector<Eigen::Vector3d>{{0.0, 0.0, 2.0}, {0.0, 40.0, 2.0}});
  const Eigen::Vector3d sensor(0.0, 3.0, 2.0);
  MapTarget target = target_of(
      street([](const Eigen::Vector3d&, const Eigen::Vector3d&) { return 0.0; }), path, sensor);
  // The map observed the street's whole space between its walls, not only its surfaces.
  for (double x = -29.75; x < 8.0; x += 0.5)
    for (double y = -7.75; y < 55.0; y += 0.5)
      for (double z = 0.25; z < 4.0; z += 0.5)
        target.observed.insert(grid_key(grid_index(Eigen::Vector3d(x, y, z), 0.5)));
  const slam::refine::GaussianCloud scan = scan_at(sensor);
  // The scan's upright points by the normals the street was made with.
  size_t upright = 0;
  for (const Eigen::Vector3d& p : scan.points)
    upright += std::abs((p + sensor).z()) > 1e-9;  // not on the ground

  const MapFit right =
      measure_map_fit(target, scan, Eigen::Isometry3d(Eigen::Translation3d(sensor)), 0.2);
  EXPECT_EQ(right.upright_observed, upright);
  // (The walls' lowest row shares its voxels with the ground: their plane is neither.)
  EXPECT_GT(right.upright_inlier_fraction, 0.9);
  EXPECT_GT(right.inlier_fraction, 0.95);

  // 3 m across the street: the ground and the walls across it fit as well as before, the
  // wall along it stands in the street's open space.
  const Eigen::Vector3d wrong = sensor - Eigen::Vector3d(3.0, 0.0, 0.0);
  const MapFit off =
      measure_map_fit(target, scan, Eigen::Isometry3d(Eigen::Translation3d(wrong)), 0.2);
  EXPECT_GT(off.inlier_fraction, 0.7);
  EXPECT_LT(off.upright_inlier_fraction, 0.6);
  EXPECT_GT(off.upright_observed, upright / 2);

  // Turned and tilted, the upright points are the same ones: the normal is read in the map's
  // frame.
  const Eigen::Isometry3d turned =
      Eigen::Translation3d(sensor) *
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 0.1, 1.0).normalized());
  slam::refine::GaussianCloud turned_scan;
  for (size_t i = 0; i < scan.size(); ++i) {
    turned_scan.points.push_back(turned.linear().transpose() * scan.points[i]);
    turned_scan.covariances.push_back(turned.linear().transpose() * scan.covariances[i] *
                                      turned.linear());
  }
  // (Points on a block's face may change block with the rounding: counted as the fit does.)
  size_t turned_upright = 0;
  for (size_t i = 0; i < scan.size(); ++i) {
    const Eigen::Vector3d q = turned * turned_scan.points[i];
    turned_upright += std::abs((scan.points[i] + sensor).z()) > 1e-9 &&
                      target.observed.count(grid_key(grid_index(q, 0.5))) != 0;
  }
  EXPECT_GT(turned_upright, upright * 9 / 10);
  EXPECT_EQ(measure_map_fit(target, turned_scan, turned, 0.2).upright_observed, turned_upright);
}

}  // namespace
}  // namespace featsense::mapping
