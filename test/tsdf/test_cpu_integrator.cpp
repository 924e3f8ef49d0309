#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "analytic_rays.hpp"
#include "featsense/config/sensor_model.hpp"
#include "tsdf_test_support.hpp"

namespace featsense::tsdf {
namespace {

using test::ObservedVoxel;

const double kOrigin[3] = {0.0, 0.0, 1.0};
const double kWallNormal[3] = {-1.0, 0.0, 0.0};  // the wall x = 5, seen from x < 5
constexpr double kWallX = 5.0;

RayBatch wall_scan() {
  return test::cast_rays(config::sensor_preset("os1-128"), kOrigin,
                         test::plane(kWallNormal, -kWallX));
}

/// Incidence below 30 degrees: there a ray's distance along itself is within a voxel of the
/// perpendicular distance near the surface.
bool facing_the_sensor(const Vec3& c) {
  return std::hypot(c.y, c.z - kOrigin[2]) < std::tan(M_PI / 6) * kWallX;
}

TEST(CpuIntegrator, PlaneGivesTheTrueSignedDistanceNearTheSurface) {
  const TsdfSettings s = test::small_map_settings();
  auto integrator = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  const IntegrationStats stats = integrator->integrate(wall_scan());
  EXPECT_GT(stats.rays, 10000u);
  EXPECT_GT(stats.voxels_updated, stats.rays);

  size_t near_checked = 0;
  size_t carved = 0;
  test::for_each_voxel(*integrator, s.truncation_m, [&](const ObservedVoxel& v) {
    const double truth = kWallX - v.centre_m.x;
    ASSERT_LE(std::abs(v.distance_m), s.truncation_m + 1e-6);
    ASSERT_LE(v.weight, s.max_weight);
    if (v.weight == 0.0f) return;
    // Nothing more than tau (plus the half diagonal of a voxel) behind the surface is touched.
    ASSERT_GE(truth, -(s.truncation_m + 0.5 * std::sqrt(3.0) * s.voxel_size_m)) << v.centre_m.x;
    if (truth > s.voxel_size_m) {
      ASSERT_GT(v.distance_m, 0.0f);
    }
    if (truth < -s.voxel_size_m) {
      ASSERT_LT(v.distance_m, 0.0f);
    }
    if (truth > s.truncation_m + 2 * s.voxel_size_m) {
      ASSERT_FLOAT_EQ(v.distance_m, s.truncation_m);  // free space carved to +tau
      ++carved;
    }
    if (std::abs(truth) <= s.voxel_size_m && facing_the_sensor(v.centre_m)) {
      ASSERT_NEAR(v.distance_m, truth, s.voxel_size_m) << v.centre_m.y << " " << v.centre_m.z;
      ++near_checked;
    }
  });
  EXPECT_GT(near_checked, 500u);
  EXPECT_GT(carved, 100000u);
}

TEST(CpuIntegrator, SphereGivesTheTrueSignedDistanceNearTheSurface) {
  const TsdfSettings s = test::small_map_settings();
  const double centre[3] = {4.0, 1.0, 1.5};
  const double radius = 1.5;
  auto integrator = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  integrator->integrate(
      test::cast_rays(config::sensor_preset("os1-128"), kOrigin, test::sphere(centre, radius)));
  size_t near_checked = 0;
  test::for_each_voxel(*integrator, s.truncation_m, [&](const ObservedVoxel& v) {
    if (v.weight == 0.0f) return;
    const double to_centre[3] = {v.centre_m.x - centre[0], v.centre_m.y - centre[1],
                                 v.centre_m.z - centre[2]};
    const double truth = std::sqrt(to_centre[0] * to_centre[0] + to_centre[1] * to_centre[1] +
                                   to_centre[2] * to_centre[2]) -
                         radius;
    // Incidence on the sphere: the angle between the outward normal and the way to the sensor.
    const double to_sensor[3] = {kOrigin[0] - v.centre_m.x, kOrigin[1] - v.centre_m.y,
                                 kOrigin[2] - v.centre_m.z};
    const double cos_incidence =
        (to_centre[0] * to_sensor[0] + to_centre[1] * to_sensor[1] + to_centre[2] * to_sensor[2]) /
        (std::sqrt(to_centre[0] * to_centre[0] + to_centre[1] * to_centre[1] +
                   to_centre[2] * to_centre[2]) *
         std::sqrt(to_sensor[0] * to_sensor[0] + to_sensor[1] * to_sensor[1] +
                   to_sensor[2] * to_sensor[2]));
    if (std::abs(truth) <= s.voxel_size_m && cos_incidence > std::cos(M_PI / 6)) {
      ASSERT_NEAR(v.distance_m, truth, s.voxel_size_m);
      ++near_checked;
    }
    if (truth > s.voxel_size_m) {
      ASSERT_GT(v.distance_m, 0.0f);
    }
  });
  EXPECT_GT(near_checked, 100u);
}

TEST(CpuIntegrator, RepeatedScansConvergeAndWeightsStopAtTheCap) {
  const TsdfSettings s = test::small_map_settings();
  auto integrator = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  const RayBatch scan = wall_scan();
  integrator->integrate(scan);
  const std::vector<uint32_t> after_one = integrator->download();
  for (int i = 0; i < 14; ++i) integrator->integrate(scan);
  const std::vector<uint32_t> after_many = integrator->download();
  size_t capped = 0;
  for (size_t i = 0; i < after_one.size(); ++i) {
    const Voxel one = unpack(after_one[i]);
    const Voxel many = unpack(after_many[i]);
    ASSERT_EQ(one.value, many.value);  // the average of a value with itself is that value
    ASSERT_LE(many.weight, s.max_weight_fixed());
    if (one.weight == kWeightScale) {
      ASSERT_EQ(many.weight, s.max_weight_fixed());
      ++capped;
    }
  }
  EXPECT_GT(capped, 100000u);
}

TEST(CpuIntegrator, InterpolationFillsBetweenScanLinesWithoutOverwritingMeasurements) {
  TsdfSettings s = test::small_map_settings();
  // A sparse sensor (vlp16: 2 degrees between beams) leaves gaps on a distant wall.
  const config::SensorModel vlp16 = config::sensor_preset("vlp16");
  const RayBatch scan = test::cast_rays(vlp16, kOrigin, test::plane(kWallNormal, -kWallX));
  auto plain = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  plain->integrate(scan);
  s.interpolation_slope = static_cast<float>(std::tan(vlp16.vertical_fov_rad() / vlp16.beams));
  auto interpolated = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  interpolated->integrate(scan);

  const std::vector<uint32_t> a = plain->download();
  const std::vector<uint32_t> b = interpolated->download();
  size_t surface_plain = 0;
  size_t surface_interpolated = 0;
  const LocalMapGeometry& g = plain->geometry();
  test::for_each_voxel(*plain, s.truncation_m, [&](const ObservedVoxel& v) {
    if (std::abs(kWallX - v.centre_m.x) > s.voxel_size_m || !facing_the_sensor(v.centre_m)) return;
    const Voxel pv = unpack(a[g.linear(v.index)]);
    const Voxel iv = unpack(b[g.linear(v.index)]);
    if (pv.weight > 0) {
      ++surface_plain;
      // Where a ray measured this voxel, interpolation left that measurement alone.
      ASSERT_EQ(pv.value, iv.value);
    }
    if (iv.weight > 0) ++surface_interpolated;
  });
  EXPECT_GT(surface_interpolated, surface_plain * 3 / 2) << surface_plain;
}

TEST(CpuIntegrator, ResultDoesNotDependOnThreadCountOrRayOrder) {
  const TsdfSettings s = test::small_map_settings();
  RayBatch scan = wall_scan();
  std::vector<uint32_t> single;
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    auto integrator = make_cpu_integrator(s, test::make_vec(0, 0, 1));
    integrator->integrate(scan);
    single = integrator->download();
  }
  auto integrator = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  std::reverse(scan.endpoints_m.begin(), scan.endpoints_m.end());
  TsdfSettings no_reduction = s;
  no_reduction.reduce_points_per_voxel = false;  // the reduction keeps the first point per voxel
  auto reversed = make_cpu_integrator(no_reduction, test::make_vec(0, 0, 1));
  auto forward = make_cpu_integrator(no_reduction, test::make_vec(0, 0, 1));
  reversed->integrate(scan);
  std::reverse(scan.endpoints_m.begin(), scan.endpoints_m.end());
  forward->integrate(scan);
  integrator->integrate(scan);
  EXPECT_TRUE(single == integrator->download());
  EXPECT_TRUE(forward->download() == reversed->download());
}

TEST(CpuIntegrator, RaysOutsideTheMapAreClippedNotLost) {
  TsdfSettings s = test::small_map_settings();
  s.map_size_m = {4.0f, 4.0f, 4.0f};  // the wall at x = 5 lies outside
  auto integrator = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  integrator->integrate(wall_scan());
  size_t observed = 0;
  test::for_each_voxel(*integrator, s.truncation_m, [&](const ObservedVoxel& v) {
    if (v.weight == 0.0f) return;
    ++observed;
    ASSERT_FLOAT_EQ(v.distance_m, s.truncation_m);  // only free space reaches the map
  });
  EXPECT_GT(observed, 1000u);
}

TEST(CpuIntegrator, BadPointsAreIgnoredAndBadBatchesRejected) {
  const TsdfSettings s = test::small_map_settings();
  RayBatch scan = wall_scan();
  auto clean = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  clean->integrate(scan);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (const Vec3 bad : {Vec3{nan, 0, 0}, Vec3{inf, 1, 1}, Vec3{1e20f, -1e20f, 3e38f},
                         Vec3{0.0f, 0.0f, 1.0f}}) {  // the last one is the origin: zero length
    scan.endpoints_m.push_back(bad);
  }
  auto dirty = make_cpu_integrator(s, test::make_vec(0, 0, 1));
  dirty->integrate(scan);
  EXPECT_TRUE(clean->download() == dirty->download());

  RayBatch wrong = wall_scan();
  wrong.origins_m.push_back(wrong.origins_m.front());  // two origins for many end points
  EXPECT_THROW(dirty->integrate(wrong), std::invalid_argument);
  EXPECT_EQ(dirty->integrate(RayBatch{}).rays, 0u);
}

}  // namespace
}  // namespace featsense::tsdf
