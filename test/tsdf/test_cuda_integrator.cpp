// The CUDA backend against the CPU integrator, voxel by voxel: the same map bit for bit (no
// voxel may differ), the same stats. Runs where a GPU is present (the GPU machine) and skips
// with a message elsewhere.

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "analytic_rays.hpp"
#include "box_room_rays.hpp"
#include "tsdf_test_support.hpp"

namespace featsense::tsdf {
namespace {

#define SKIP_WITHOUT_GPU()                                                \
  do {                                                                    \
    std::string why;                                                      \
    if (!cuda_backend_available(&why)) GTEST_SKIP() << "no GPU: " << why; \
  } while (false)

struct Difference {
  size_t differing = 0;
  int max_value_units = 0;
  int max_weight_units = 0;
};

Difference compare(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  Difference d;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] == b[i]) continue;
    ++d.differing;
    const Voxel x = unpack(a[i]);
    const Voxel y = unpack(b[i]);
    d.max_value_units = std::max(d.max_value_units, std::abs(x.value - y.value));
    d.max_weight_units = std::max(d.max_weight_units, std::abs(x.weight - y.weight));
  }
  return d;
}

void expect_same_map(const TsdfSettings& settings, const std::vector<RayBatch>& scans,
                     const char* what) {
  auto cpu = make_cpu_integrator(settings, test::make_vec(0, 0, 1.5));
  auto gpu = make_cuda_integrator(settings, test::make_vec(0, 0, 1.5));
  for (const RayBatch& scan : scans) {
    const IntegrationStats a = cpu->integrate(scan);
    const IntegrationStats b = gpu->integrate(scan);
    EXPECT_EQ(a.rays, b.rays) << what;
    EXPECT_EQ(a.voxels_updated, b.voxels_updated) << what;
  }
  const std::vector<uint32_t> reference = cpu->download();
  const Difference d = compare(reference, gpu->download());
  size_t observed = 0;
  for (uint32_t v : reference) observed += unpack(v).weight > 0 ? 1 : 0;
  std::printf(
      "[ parity   ] %s: %zu of %zu observed voxels differ (max %d value units, %d weight units)\n",
      what, d.differing, observed, d.max_value_units, d.max_weight_units);
  EXPECT_GT(observed, 5000u) << what;
  EXPECT_EQ(d.differing, 0u) << what;
}

TEST(CudaIntegrator, SameMapAsTheCpuIntegratorOnAnalyticSurfaces) {
  SKIP_WITHOUT_GPU();
  const double origin[3] = {0.0, 0.0, 1.0};
  const double normal[3] = {-1.0, 0.0, 0.0};
  const double centre[3] = {4.0, 1.0, 1.5};
  const config::SensorModel os1 = config::sensor_preset("os1-128");
  TsdfSettings s = test::small_map_settings();
  RayBatch plane = test::cast_rays(os1, origin, test::plane(normal, -5.0));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Points no sensor should report, which both backends must ignore alike.
  plane.endpoints_m.push_back({nan, 1.0f, 1.0f});
  plane.endpoints_m.push_back({std::numeric_limits<float>::infinity(), 0.0f, 0.0f});
  plane.endpoints_m.push_back({1e20f, -1e20f, 3e38f});
  expect_same_map(s, {plane}, "plane and bad points");
  s.interpolation_slope = static_cast<float>(std::tan(os1.vertical_fov_rad() / os1.beams));
  expect_same_map(s, {test::cast_rays(os1, origin, test::sphere(centre, 1.5))}, "sphere+interp");
}

TEST(CudaIntegrator, SameMapAsTheCpuIntegratorOnAMovingSensor) {
  SKIP_WITHOUT_GPU();
  const std::vector<RayBatch> scans = test::box_room_rays(4, false);
  TsdfSettings s;  // the default 40 x 40 x 15 m map at 6.4 cm
  s.interpolation_slope = static_cast<float>(std::tan(0.785398 / 128));
  expect_same_map(s, scans, "box room, default map, interpolation, reduction");
  s.reduce_points_per_voxel = false;
  s.map_size_m = {12.0f, 12.0f, 6.0f};  // rays leave this map: clipping is exercised too
  expect_same_map(s, scans, "box room, small map, every ray");
  std::vector<RayBatch> flagged = scans;
  for (RayBatch& scan : flagged) {
    scan.interpolate.resize(scan.size());
    for (size_t i = 0; i < scan.size(); ++i) scan.interpolate[i] = i % 3 == 0 ? 0 : 1;
  }
  expect_same_map(s, flagged, "box room, small map, every third ray not interpolating");
  // Sparse carving: each ray's walk ends where its carving level says, on both backends.
  s.dense_range_m = 4.0f * 2.6f;  // most of the room: many walks end early
  expect_same_map(s, test::box_room_rays(4, false, true), "box room, small map, sparse carving");
  s.carve_free_space = false;
  expect_same_map(s, test::box_room_rays(4, false, true), "box room, small map, band only");
}

TEST(CudaIntegrator, SameMapAsTheCpuIntegratorWithSettledFreeSpace) {
  SKIP_WITHOUT_GPU();
  // A weight cap of 2: free space seen twice is settled and passed by, on both backends.
  TsdfSettings s = test::small_map_settings();
  s.max_weight = 2.0f;
  const std::vector<RayBatch> scans = test::box_room_passes(2, 3);
  expect_same_map(s, scans, "box room, small map, settled free space");
  TsdfSettings interpolating = s;  // interpolated candidates pass settled free space by too
  interpolating.interpolation_slope = 0.03f;
  expect_same_map(interpolating, scans, "box room, small map, settled free space, interpolation");
  // The CPU map written into the GPU's, brick by brick (as a shift loads the store): the
  // settled bits follow, so the next scan counts the same updates.
  auto cpu = make_cpu_integrator(s, test::make_vec(0, 0, 1.5));
  for (const RayBatch& scan : scans) cpu->integrate(scan);
  auto gpu = make_cuda_integrator(s, test::make_vec(0, 0, 1.5));
  test::copy_all_bricks(*cpu, *gpu);
  EXPECT_EQ(cpu->integrate(scans.front()).voxels_updated,
            gpu->integrate(scans.front()).voxels_updated);
  const Difference d = compare(cpu->download(), gpu->download());
  std::printf("[ parity   ] after write_bricks: %zu voxels differ\n", d.differing);
  EXPECT_EQ(d.differing, 0u);
}

TEST(CudaIntegrator, ReportsItsDeviceMemory) {
  SKIP_WITHOUT_GPU();
  const TsdfSettings s;
  auto gpu = make_cuda_integrator(s, test::make_vec(0, 0, 0));
  const size_t volume = s.map_dim().x * static_cast<size_t>(s.map_dim().y) * s.map_dim().z * 4;
  EXPECT_GE(gpu->memory_bytes(), 2 * volume);
  EXPECT_EQ(gpu->backend_name(), "cuda");
}

TEST(CudaIntegrator, RefusesAMapOfMoreThanTwoToThe32Voxels) {
  SKIP_WITHOUT_GPU();
  TsdfSettings s;
  s.map_size_m = {300.0f, 300.0f, 30.0f};  // 4688 x 4688 x 472 voxels at 6.4 cm: 1.0e10
  try {
    make_cuda_integrator(s, test::make_vec(0, 0, 0));
    ADD_FAILURE() << "no error for a map of 1e10 voxels";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at most 2^32"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace featsense::tsdf
