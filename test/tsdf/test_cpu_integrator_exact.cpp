// The CPU integrator's exact output, bit for bit. The CUDA backend is checked against the CPU
// integrator on the GPU machine, so any change to the CPU map (a voxel value, a weight, a
// count) breaks that parity even where no test here would notice. Two checks per case:
// - against the reference integrator (reference_integrator.hpp: one thread, a plain minimum,
//   fusion of a list of touched voxels), which shares only ray_marcher.hpp and voxel.hpp with
//   the fast integrators, the definitions the CUDA kernels compile too;
// - against hashes of the map and stats recorded with the integrator as it was before its
//   speed work (commit 51f32ca), so a change of the shared definitions shows up as well.
//   Recorded again where the walks began to measure t in integer ticks (ray_marcher.hpp,
//   WalkClock) instead of float sums: where a ray passes within a tick or a float's rounding
//   of a voxel edge, which of the voxels there it enters first may differ, and with it a few
//   candidates.

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>

#include "analytic_rays.hpp"
#include "box_room_rays.hpp"
#include "cpu_fast/free_space_walk.hpp"
#include "featsense/tsdf/reference_integrator.hpp"
#include "ray_marcher.hpp"
#include "ray_walk.hpp"
#include "tsdf_test_support.hpp"
#include "varied_rays.hpp"

namespace featsense::tsdf {
namespace {

/// FNV-1a over 32-bit words.
uint64_t fnv1a(uint64_t hash, uint64_t word) {
  hash ^= word;
  return hash * 0x100000001b3ull;
}

/// Integrates `scans` with the CPU integrator and the reference one, expects the same map
/// and stats after every scan, and returns a hash of the CPU integrator's maps and stats.
/// `updated`, if given, receives each scan's count of updated voxels.
uint64_t expect_same_as_reference(const TsdfSettings& settings, Vec3 centre_m,
                                  const std::vector<RayBatch>& scans,
                                  std::vector<size_t>* updated = nullptr) {
  auto cpu = make_cpu_integrator(settings, centre_m);
  ReferenceIntegrator reference(settings, centre_m);
  uint64_t hash = 0xcbf29ce484222325ull;
  for (const RayBatch& scan : scans) {
    const IntegrationStats a = cpu->integrate(scan);
    const IntegrationStats b = reference.integrate(scan);
    EXPECT_EQ(a.rays, b.rays);
    EXPECT_EQ(a.voxels_updated, b.voxels_updated);
    if (updated != nullptr) updated->push_back(a.voxels_updated);
    const std::vector<uint32_t> map = cpu->download();
    size_t differing = 0;
    for (size_t i = 0; i < map.size(); ++i) differing += map[i] != reference.map()[i] ? 1 : 0;
    EXPECT_EQ(differing, 0u) << "of " << map.size() << " voxels";
    hash = fnv1a(hash, a.rays);
    hash = fnv1a(hash, a.voxels_updated);
    for (const uint32_t v : map) hash = fnv1a(hash, v);
  }
  std::printf("[ hash     ] 0x%016llx\n", static_cast<unsigned long long>(hash));
  return hash;
}

float os1_interpolation_slope() {
  const config::SensorModel os1 = config::sensor_preset("os1-128");
  return static_cast<float>(std::tan(os1.vertical_fov_rad() / os1.beams));
}

/// The settings the hashes were recorded with: the default map, tau 0.6 m.
TsdfSettings settings_of_the_hashes() {
  TsdfSettings s;
  s.truncation_m = 0.6f;
  return s;
}

TEST(CpuIntegratorExact, IndoorDefaultMapInterpolationReduction) {
  TsdfSettings s = settings_of_the_hashes();  // the 40 x 40 x 15 m map at 6.4 cm
  s.interpolation_slope = os1_interpolation_slope();
  EXPECT_EQ(expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_rays(3, false)),
            0x56f0ec1ec7433416ull);
}

TEST(CpuIntegratorExact, OutdoorRaysLeaveTheMap) {
  TsdfSettings s = settings_of_the_hashes();
  s.map_size_m = {20.0f, 16.0f, 8.0f};
  s.interpolation_slope = os1_interpolation_slope();
  EXPECT_EQ(expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_rays(3, true)),
            0x644262c315719dceull);
}

TEST(CpuIntegratorExact, EveryRayNoInterpolation) {
  TsdfSettings s = settings_of_the_hashes();
  s.map_size_m = {24.0f, 24.0f, 8.0f};
  s.reduce_points_per_voxel = false;
  EXPECT_EQ(expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_rays(2, false)),
            0xdb44c65456707cbcull);
}

TEST(CpuIntegratorExact, EveryRayWithInterpolation) {
  TsdfSettings s = test::small_map_settings();
  s.reduce_points_per_voxel = false;
  s.interpolation_slope = os1_interpolation_slope();
  EXPECT_EQ(expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_rays(2, false)),
            0x632eb59c678b29bdull);
}

TEST(CpuIntegratorExact, RaysThatMayNotInterpolate) {
  TsdfSettings s = settings_of_the_hashes();
  s.map_size_m = {24.0f, 24.0f, 8.0f};
  s.interpolation_slope = os1_interpolation_slope();
  std::vector<RayBatch> scans = test::box_room_rays(2, false);
  for (RayBatch& scan : scans) {
    // Every third ray without interpolation: the flag, not a pattern of the scan, decides.
    scan.interpolate.resize(scan.size());
    for (size_t i = 0; i < scan.size(); ++i) scan.interpolate[i] = i % 3 == 0 ? 0 : 1;
  }
  const uint64_t flagged = expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), scans);
  for (RayBatch& scan : scans) scan.interpolate.clear();
  EXPECT_NE(flagged, expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), scans));
}

TEST(CpuIntegratorExact, SparseCarving) {
  // Rays of the lattice carve nearer the sensor than the others, each walk ends where its
  // level says: the CPU walk must end where march_ray does, on a map rays also leave.
  TsdfSettings s = TsdfSettings::from_config(config::MapConfig{}, config::sensor_preset("os1-128"));
  ASSERT_GT(s.dense_range_m, 1.0f);
  s.map_size_m = {24.0f, 24.0f, 8.0f};
  expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_rays(2, false, true));
  s.dense_range_m *= 4.0f;  // most of the room within the dense range
  s.reduce_points_per_voxel = false;
  expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_rays(2, false, true));
  s.carve_free_space = false;  // the band only
  expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_rays(2, false, true));
}

TEST(CpuIntegratorExact, RaysFromOutsideTheMap) {
  // A 8 x 8 x 4 m map ahead of the sensor: rays enter it from outside, some only pass it.
  TsdfSettings s = settings_of_the_hashes();
  s.map_size_m = {8.0f, 8.0f, 4.0f};
  s.interpolation_slope = os1_interpolation_slope();
  EXPECT_EQ(expect_same_as_reference(s, test::make_vec(5, 2, 1.0), test::box_room_rays(2, false)),
            0x4761511e2fed3bc0ull);
}

TEST(CpuIntegratorExact, SameMapWithAnyNumberOfThreads) {
  // The CPU integrator shares the map out among sectors by its thread count: one thread
  // (eight sectors), seven (56 sectors, more candidates handed between them) and forty (as many
  // sectors as a brick's owner byte allows, 255) must give the same map as the reference
  // integrator.
  TsdfSettings s = settings_of_the_hashes();
  s.map_size_m = {16.0f, 16.0f, 6.0f};
  s.interpolation_slope = os1_interpolation_slope();
  const std::vector<RayBatch> scans = test::box_room_rays(2, false);
  for (const int threads : {1, 7, 40}) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      EXPECT_EQ(expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), scans),
                0xe1dc5e336dc1c7b3ull)
          << threads << " threads";
    });
  }
}

TEST(CpuIntegratorExact, RepeatedScansReachTheWeightCapWithOneOrigin) {
  // One origin for the whole scan, the same scan again and again: weights reach the cap, and
  // values behind the surface get partial weights. Bad points are in the batch too.
  TsdfSettings s = test::small_map_settings();
  s.max_weight = 4.0f;
  s.interpolation_slope = os1_interpolation_slope();
  const double origin[3] = {0.3, -0.2, 1.1};
  const double centre[3] = {3.0, 1.0, 1.5};
  RayBatch scan =
      test::cast_rays(config::sensor_preset("os1-128"), origin, test::sphere(centre, 1.5));
  const double normal[3] = {-0.9, 0.1, 0.1};
  const RayBatch wall =
      test::cast_rays(config::sensor_preset("os1-128"), origin, test::plane(normal, -4.0));
  scan.endpoints_m.insert(scan.endpoints_m.end(), wall.endpoints_m.begin(), wall.endpoints_m.end());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  scan.endpoints_m.push_back({nan, 1.0f, 1.0f});
  scan.endpoints_m.push_back({std::numeric_limits<float>::infinity(), 0.0f, 0.0f});
  scan.endpoints_m.push_back({1e20f, -1e20f, 3e38f});
  scan.endpoints_m.push_back(scan.origins_m.front());
  scan.up = test::make_vec(0.1 / std::sqrt(1.01), 0.0, 1.0 / std::sqrt(1.01));  // a tilted sensor
  const std::vector<RayBatch> scans(6, scan);
  // Recorded after settled free space was passed by (the maps were those of the hash before,
  // 0x6708b25316a676c5 at commit 51f32ca, the counts of updated voxels smaller once the
  // weights reach the cap), and again with the walks' integer ticks.
  EXPECT_EQ(expect_same_as_reference(s, test::make_vec(0, 0, 1), scans), 0x7ae498c2842b45a9ull);
}

TEST(CpuIntegratorExact, SettledFreeSpaceIsPassedBy) {
  TsdfSettings s = test::small_map_settings();
  s.max_weight = 2.0f;
  std::vector<size_t> updated;
  expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_passes(2, 3), &updated);
  // Once the free space is settled, a scan updates little more than its truncation band.
  EXPECT_LT(updated.back() * 3, updated.front());
  // With vertical interpolation, whose candidates settled free space passes by as well (a
  // wide band, so that rays of the small room interpolate at 0.1 m voxels).
  s.interpolation_slope = 0.03f;
  expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_passes(2, 3));
}

TEST(CpuIntegratorExact, SettledFreeSpaceAtTheDefaultVoxelSize) {
  // The sensor's own interpolation band at 6.4 cm voxels (it reaches a neighbouring voxel
  // beyond 10.4 m, so the room's far walls are interpolated), with a map that holds the room.
  TsdfSettings s;
  s.map_size_m = {28.0f, 28.0f, 6.0f};
  s.max_weight = 2.0f;
  s.interpolation_slope = os1_interpolation_slope();
  std::vector<size_t> updated;
  expect_same_as_reference(s, test::make_vec(-2, 0, 1.5), test::box_room_passes(2, 3), &updated);
  EXPECT_LT(updated.back() * 3, updated.front());
}

TEST(CpuIntegratorExact, BricksWrittenBackKeepTheirSettledFreeSpace) {
  // A map that moved into another integrator (as bricks loaded from the store do) passes its
  // settled free space by as the original does: same counts, same map.
  TsdfSettings s = test::small_map_settings();
  s.max_weight = 2.0f;
  const std::vector<RayBatch> scans = test::box_room_passes(2, 3);
  auto original = make_cpu_integrator(s, test::make_vec(-2, 0, 1.5));
  for (size_t i = 0; i + 1 < scans.size(); ++i) original->integrate(scans[i]);
  auto copy = make_cpu_integrator(s, test::make_vec(-2, 0, 1.5));
  test::copy_all_bricks(*original, *copy);
  EXPECT_EQ(original->integrate(scans.back()).voxels_updated,
            copy->integrate(scans.back()).voxels_updated);
  EXPECT_TRUE(original->download() == copy->download());
}

struct Visit {
  size_t index;
  int32_t value;
  bool interpolated;
  bool operator==(const Visit& o) const {
    return index == o.index && value == o.value && interpolated == o.interpolated;
  }
};

TEST(WalkClock, TicksAreClampedAndNeverDecrease) {
  const detail::WalkClock clock{static_cast<float>(detail::kWalkTicks) / 40.0f};  // a 40 m walk
  EXPECT_EQ(clock.ticks(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(clock.ticks(-1.0f), 0);
  EXPECT_EQ(clock.ticks(0.0f), 0);
  EXPECT_EQ(clock.ticks(40.0f), detail::kWalkTicks);
  EXPECT_EQ(clock.ticks(40.01f), detail::kBeyondWalk);
  EXPECT_EQ(clock.ticks(std::numeric_limits<float>::infinity()), detail::kBeyondWalk);
  EXPECT_EQ(clock.ticks(std::numeric_limits<float>::max()), detail::kBeyondWalk);
  int32_t last = 0;
  for (float t = 0.0f; t < 41.0f; t += 0.0137f) {
    const int32_t ticks = clock.ticks(t);
    EXPECT_GE(ticks, last) << t;
    last = ticks;
  }
}

TEST(WalkClock, AxisCrossingsMoveOnOrNeverCome) {
  const float vs = 0.064f;
  // A walk of 2 mm: the spacing of crossings is far beyond its end, clamped.
  const detail::WalkClock short_walk{static_cast<float>(detail::kWalkTicks) / 0.002f};
  const detail::AxisCrossings c = detail::axis_crossings(0.01f, 0.3f, 0, vs, short_walk);
  EXPECT_EQ(c.step, 1);
  EXPECT_EQ(c.delta, detail::kBeyondWalk);
  // A walk along no part of the axis never crosses it.
  const detail::WalkClock clock{static_cast<float>(detail::kWalkTicks) / 30.0f};
  const detail::AxisCrossings parallel = detail::axis_crossings(1.0f, 0.0f, 15, vs, clock);
  EXPECT_EQ(parallel.step, 0);
  EXPECT_EQ(parallel.first, detail::kBeyondWalk);
  EXPECT_EQ(parallel.delta, detail::kBeyondWalk);
  // A steep axis: crossings a voxel apart along it, at least a tick apart whatever the slope.
  const detail::AxisCrossings backwards = detail::axis_crossings(1.0f, -1.0f, 15, vs, clock);
  EXPECT_EQ(backwards.step, -1);
  EXPECT_GE(backwards.first, 0);
  EXPECT_NEAR(static_cast<double>(backwards.delta), vs / 30.0 * detail::kWalkTicks, 2.0);
  const detail::AxisCrossings grazing = detail::axis_crossings(1.0f, 1e-12f, 15, vs, clock);
  EXPECT_EQ(grazing.delta, detail::kBeyondWalk);
}

TEST(CpuIntegratorExact, JumpsAcrossSettledBricksLeaveTheWalkExact) {
  // The walk both backends run jumps across bricks of settled free space. Leaving out the
  // candidates it would pass by anyway (+tau in a settled brick), it must propose what
  // march_ray proposes, in the same order. Rays along diagonals from voxel corners tie at every
  // face crossing.
  TsdfSettings s;
  const LocalMapGeometry map = centred_geometry(s, test::make_vec(0, 0, 1.5));
  std::vector<uint8_t> settled(map.voxel_count() / kBrickVoxels);
  std::mt19937 random(7);
  for (uint8_t& brick : settled) brick = random() % 4 != 0 ? 1 : 0;
  detail::RayMarchParams params;
  params.truncation_m = s.truncation_m;
  params.interpolation_slope = 0.006f;
  const auto passed_by = [&](const Visit& v) {
    return v.value == kValueScale && settled[v.index / kBrickVoxels] != 0;
  };

  std::vector<std::pair<Vec3, Vec3>> rays;  // origin, end point
  const float corner = 8 * s.voxel_size_m;  // a brick corner; the next one a voxel corner
  const float vs = s.voxel_size_m;
  for (const Vec3 origin : {test::make_vec(0, 0, 0), test::make_vec(corner, corner, corner),
                            Vec3{3 * vs, 0, 5 * vs}, test::make_vec(0.01, -0.02, 1.5)}) {
    for (const Vec3 d : {test::make_vec(1, 1, 0), test::make_vec(-1, 1, 0), test::make_vec(1, 1, 1),
                         test::make_vec(-1, -1, -1), test::make_vec(1, 0, 0),
                         test::make_vec(0, -1, 0.5), test::make_vec(0.3, 0.3, -0.1)}) {
      rays.emplace_back(origin, origin + (12.0f / norm(d)) * d);
    }
  }
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  for (int k = 0; k < 400; ++k) {
    const Vec3 origin = test::make_vec(uniform(random), uniform(random), 1.5 + uniform(random));
    const Vec3 d{uniform(random), uniform(random), 0.3f * uniform(random)};
    rays.emplace_back(origin, origin + (2.0f + 16.0f * std::fabs(uniform(random))) * d);
  }

  // What a walk proposes: all of it counted, what is not passed by kept in order.
  struct Recorder {
    std::vector<Visit> kept;
    size_t all = 0;
  };
  const auto record = [&](Recorder& r) {
    return [&](size_t i, int32_t v, bool interp) {
      ++r.all;
      if (!passed_by({i, v, interp})) r.kept.push_back({i, v, interp});
    };
  };
  size_t jumped = 0;
  for (const auto& [origin, endpoint] : rays) {
    // march_ray, which never jumps, and walk_ray, which both backends run, jumping.
    Recorder reference;
    Recorder walk;
    detail::march_ray(origin, endpoint, map, params, record(reference));
    detail::walk_ray(origin, endpoint, map, params, record(walk), settled.data());
    jumped += reference.all - walk.all;
    EXPECT_TRUE(walk.kept == reference.kept)
        << "ray from " << origin.x << " " << origin.y << " " << origin.z << " to " << endpoint.x
        << " " << endpoint.y << " " << endpoint.z;
  }
  EXPECT_GT(jumped, 10000u);  // the jumps were taken
}

/// A walk's parameters: tau, the interpolation slope (0: none), sparse carving from (0: none).
detail::RayMarchParams varied_params(float truncation_m, float slope, float carve_from_m) {
  detail::RayMarchParams params;
  params.truncation_m = truncation_m;
  params.interpolation_slope = slope;
  params.carve_from_m = carve_from_m;
  return params;
}

TEST(CpuIntegratorExact, AWalkInPartsVisitsWhatTheWholeWalkVisits) {
  // The GPU walks rays in parts (WalkPart), each starting where the whole walk would be at its
  // first tick. Together, in order, they must propose exactly what the whole walk proposes: the
  // same sequence without settled bricks; with them, the same candidates that are not passed
  // by (a part may start inside a settled brick and jump from there). Rays from inside and
  // outside the map, ending inside and beyond it, with and without sparse carving.
  TsdfSettings s;
  const LocalMapGeometry map = centred_geometry(s, test::make_vec(0, 0, 1.5));
  std::vector<uint8_t> settled(map.voxel_count() / kBrickVoxels);
  std::mt19937 random(11);
  for (uint8_t& brick : settled) brick = random() % 3 != 0 ? 1 : 0;
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  size_t visits = 0;
  for (int k = 0; k < 300; ++k) {
    const float reach = k % 3 == 0 ? 30.0f : 18.0f;  // the map reaches 20 m from its centre
    const Vec3 origin = test::make_vec(reach * uniform(random), reach * uniform(random),
                                       1.5 + 2.0f * uniform(random));
    const Vec3 d{uniform(random), uniform(random), 0.2f * uniform(random)};
    const Vec3 endpoint = origin + (1.0f + 30.0f * std::fabs(uniform(random))) * d;
    const detail::RayMarchParams params =
        varied_params(s.truncation_m, k % 2 == 0 ? 0.006f : 0.0f, k % 4 == 1 ? 3.0f : 0.0f);
    const uint8_t* const brick_sets[] = {nullptr, settled.data()};
    for (const uint8_t* bricks : brick_sets) {
      const auto passed_by = [&](const Visit& v) {
        return bricks != nullptr && v.value == kValueScale && bricks[v.index / kBrickVoxels] != 0;
      };
      std::vector<Visit> whole;
      const auto record = [&](std::vector<Visit>& out) {
        return [&](size_t i, int32_t v, bool interp) {
          if (!passed_by({i, v, interp})) out.push_back({i, v, interp});
        };
      };
      detail::walk_ray(origin, endpoint, map, params, record(whole), bricks);
      visits += whole.size();
      for (const int32_t count : {2, 3, 7}) {
        std::vector<Visit> parts;
        for (int32_t index = 0; index < count; ++index) {
          detail::walk_ray(origin, endpoint, map, params, record(parts), bricks,
                           detail::WalkPart{index, count});
        }
        EXPECT_TRUE(parts == whole) << count << " parts, ray " << k << (bricks ? ", settled" : "");
      }
    }
  }
  EXPECT_GT(visits, 50000u);
}

/// What a walk proposes: the free space as a set, the rest in order.
struct Proposals {
  std::set<size_t> free;
  std::vector<Visit> other;
  size_t words = 0;  // free space handed over as words
};

/// A visitor that takes the free space at the end of a walk whole (kTakesFreeWalks) and walks
/// it as words with the scalar loop, as the CPU integrator does where the processor has no
/// AVX2, leaving out what settled bricks pass by; march_ray, which hands it every voxel on its
/// own, is recorded with the same visitor.
struct FreeWordVisitor {
  static constexpr bool kTakesFreeWalks = true;
  Proposals* out;
  const uint8_t* bricks;
  detail::FreeSpaceMap map;
  void operator()(size_t index, int32_t value, bool interpolated) {
    if (value == kValueScale && !interpolated) {
      free(index);
    } else {
      out->other.push_back({index, value, interpolated});
    }
  }
  void free_walk(const detail::FreeWalk& walk) {
    detail::walk_free_space_job(walk, map, bricks, *this);
  }
  void free_word(size_t word, uint64_t bits) {
    ++out->words;
    for (; bits != 0; bits &= bits - 1)
      free(word * 64 + static_cast<size_t>(__builtin_ctzll(bits)));
  }
  void free(size_t index) {
    if (bricks == nullptr || bricks[index / kBrickVoxels] == 0) out->free.insert(index);
  }
};

TEST(CpuIntegratorExact, FreeSpaceWalkedAsWordsIsTheWalksFreeSpace) {
  // Where the processor has no AVX2, the CPU walks the free space at the end of a walk in a
  // loop of its own (free_space_walk.hpp), which hands it on as words. The free space it proposes
  // must be exactly the set march_ray proposes (less what settled bricks pass by), and every other
  // candidate the same, in the same order. Rays along diagonals from brick corners tie at every
  // crossing; steep rays step along z most; rays from outside the map, ending beyond it, with
  // sparse carving, with and without settled bricks.
  TsdfSettings s;
  const LocalMapGeometry map = centred_geometry(s, test::make_vec(0, 0, 1.5));
  std::vector<uint8_t> settled(map.voxel_count() / kBrickVoxels);
  std::mt19937 random(13);
  for (uint8_t& brick : settled) brick = random() % 3 == 0 ? 1 : 0;

  const std::vector<std::pair<Vec3, Vec3>> rays =
      test::varied_rays(s.voxel_size_m, 5.5f, 600, random);

  size_t free_voxels = 0;
  size_t words = 0;
  for (size_t k = 0; k < rays.size(); ++k) {
    const auto& [origin, endpoint] = rays[k];
    const detail::RayMarchParams params =
        varied_params(s.truncation_m, k % 2 == 0 ? 0.006f : 0.0f, k % 3 == 1 ? 2.5f : 0.0f);
    const uint8_t* const brick_sets[] = {nullptr, settled.data()};
    for (const uint8_t* bricks : brick_sets) {
      Proposals reference;
      Proposals walk;
      const detail::FreeSpaceMap free_map = detail::FreeSpaceMap::of(map);
      detail::march_ray(origin, endpoint, map, params,
                        FreeWordVisitor{&reference, bricks, free_map});
      FreeWordVisitor visitor{&walk, bricks, free_map};
      detail::walk_ray(origin, endpoint, map, params, visitor, bricks);
      free_voxels += reference.free.size();
      words += walk.words;
      EXPECT_TRUE(walk.free == reference.free) << "ray " << k << (bricks ? ", settled" : "");
      EXPECT_TRUE(walk.other == reference.other) << "ray " << k << (bricks ? ", settled" : "");
    }
  }
  EXPECT_GT(free_voxels, 100000u);
  EXPECT_GT(words, 10000u);  // the free space was walked as words
}

}  // namespace
}  // namespace featsense::tsdf
