// Sparse carving (TsdfSettings::dense_range_m) and no carving (carve_free_space) against full
// carving on the same scan: they may only leave out free-space voxels; sparse carving only few
// of them, near the sensor.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "box_room_rays.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf {
namespace {

struct Comparison {
  size_t full_observed = 0;   ///< voxels full carving updated
  size_t band_differing = 0;  ///< voxels not at +tau under full carving that differ
  size_t free_differing = 0;  ///< voxels at +tau under full carving, other values here
  size_t extra = 0;           ///< voxels only sparse carving updated
  size_t missed = 0;          ///< free voxels only full carving updated
  float farthest_missed_m = 0.0f;
};

float distance(Vec3 a, Vec3 b) { return norm(a - b); }

/// Calls visit(global index, storage index) for every voxel of the map.
template <typename Visit>
void for_each_voxel(const LocalMapGeometry& g, const Visit& visit) {
  for (int32_t z = g.origin.z; z < g.origin.z + g.dim.z; ++z) {
    for (int32_t y = g.origin.y; y < g.origin.y + g.dim.y; ++y) {
      for (int32_t x = g.origin.x; x < g.origin.x + g.dim.x; ++x)
        visit(Index3{x, y, z}, g.linear({x, y, z}));
    }
  }
}

Comparison compare_one_scan(TsdfSettings settings, const RayBatch& scan, Vec3 sensor) {
  TsdfSettings full_settings = settings;
  full_settings.dense_range_m = 0.0f;
  full_settings.carve_free_space = true;
  auto full = make_cpu_integrator(full_settings, sensor);
  auto sparse = make_cpu_integrator(settings, sensor);
  full->integrate(scan);
  sparse->integrate(scan);
  const std::vector<uint32_t> a = full->download();
  const std::vector<uint32_t> b = sparse->download();
  Comparison c;
  for_each_voxel(full->geometry(), [&](Index3 voxel, size_t i) {
    const Vec3 centre = full->geometry().centre_of(voxel);
    const Voxel va = unpack(a[i]);
    const Voxel vb = unpack(b[i]);
    c.full_observed += va.weight > 0 ? 1 : 0;
    if (va.weight == 0) {
      c.extra += vb.weight > 0 ? 1 : 0;
    } else if (va.value != kValueScale) {
      c.band_differing += a[i] != b[i] ? 1 : 0;
    } else if (vb.weight == 0) {
      ++c.missed;
      c.farthest_missed_m = std::max(c.farthest_missed_m, distance(centre, sensor));
    } else {
      c.free_differing += a[i] != b[i] ? 1 : 0;
    }
  });
  std::printf(
      "[ sparse   ] %zu voxels observed, %zu missed (%.3f %%) up to %.2f m from the sensor\n",
      c.full_observed, c.missed, 100.0 * static_cast<double>(c.missed) / c.full_observed,
      c.farthest_missed_m);
  return c;
}

/// The pipeline's settings for an OS1-128, on a map just larger than the box room.
TsdfSettings os1_settings() {
  TsdfSettings s = TsdfSettings::from_config(config::MapConfig{}, config::sensor_preset("os1-128"));
  s.map_size_m = {24.0f, 24.0f, 8.0f};
  return s;
}

TEST(SparseCarving, LeavesOutOnlyFewFreeVoxelsNearTheSensor) {
  const TsdfSettings s = os1_settings();
  ASSERT_GT(s.dense_range_m, 2.0f);
  const RayBatch scan = test::box_room_rays(1, false, true).front();
  const Comparison c = compare_one_scan(s, scan, scan.origins_m.front());
  EXPECT_EQ(c.band_differing, 0u) << "surfaces and the band must not change";
  EXPECT_EQ(c.free_differing, 0u);
  EXPECT_EQ(c.extra, 0u);
  EXPECT_GT(c.full_observed, 1000000u);
  EXPECT_LT(static_cast<double>(c.missed), 0.01 * static_cast<double>(c.full_observed));
  // Beyond the dense range (and the sensor's travel during the scan) every ray carves.
  EXPECT_LT(c.farthest_missed_m, s.dense_range_m + 0.5f);
}

TEST(SparseCarving, WithoutLevelsEveryRayCarvesAllTheWay) {
  const TsdfSettings s = os1_settings();
  const RayBatch scan = test::box_room_rays(1, false, false).front();
  const Comparison c = compare_one_scan(s, scan, scan.origins_m.front());
  EXPECT_EQ(c.band_differing + c.free_differing + c.extra + c.missed, 0u);
}

TEST(FreeSpaceCarving, OffKeepsTheBandAndLeavesFreeSpaceAlone) {
  TsdfSettings s = os1_settings();
  s.carve_free_space = false;
  const RayBatch scan = test::box_room_rays(1, false, true).front();
  const Comparison c = compare_one_scan(s, scan, scan.origins_m.front());
  EXPECT_EQ(c.band_differing, 0u) << "surfaces and the band must not change";
  EXPECT_EQ(c.extra, 0u);
  EXPECT_GT(static_cast<double>(c.missed), 0.7 * static_cast<double>(c.full_observed));
  // Cells that only vertical interpolation filled keep their value where, with carving, a
  // ray passing through them in free space would have overruled it (a measurement beats an
  // interpolation): a few.
  EXPECT_GT(c.free_differing, 0u);
  EXPECT_LT(static_cast<double>(c.free_differing), 0.01 * static_cast<double>(c.full_observed));
}

TEST(SparseCarving, RaysOfLevelZeroStopCarvingAtTheDenseRange) {
  // One ray of level 0 along +x through an empty map: its free voxels start two voxels
  // before the dense range (the walk's margin), where full carving reaches the sensor.
  TsdfSettings s = os1_settings();
  s.dense_range_m = 2.0f;
  s.interpolation_slope = 0.0f;
  RayBatch ray;
  ray.origins_m = {{0.032f, 0.032f, 0.032f}};
  ray.endpoints_m = {{8.032f, 0.032f, 0.032f}};
  ray.carving_level = {0};
  auto integrator = make_cpu_integrator(s, ray.origins_m.front());
  const size_t sparse_updated = integrator->integrate(ray).voxels_updated;
  const std::vector<uint32_t> map = integrator->download();
  float nearest = 1e9f;
  for_each_voxel(integrator->geometry(), [&](Index3 voxel, size_t i) {
    if (unpack(map[i]).weight > 0)
      nearest = std::min(nearest, integrator->geometry().centre_of(voxel).x);
  });
  EXPECT_NEAR(nearest, 2.0f - 2.0f * s.voxel_size_m, s.voxel_size_m);
  ray.carving_level = {kFullCarvingLevel};
  auto full = make_cpu_integrator(s, ray.origins_m.front());
  // 8 m + tau of the ray against 6 m + tau + 2 voxels: about 28 voxels fewer.
  EXPECT_GT(full->integrate(ray).voxels_updated, sparse_updated + 20);
}

}  // namespace
}  // namespace featsense::tsdf
