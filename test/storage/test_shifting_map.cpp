// The local map that follows the sensor: mapping with a small map that shifts many times (in
// every axis and direction, and back into mapped space) gives the same global map, voxel for
// voxel, as one large map that never shifts; continuing from a store gives the same map as
// one uninterrupted run. On the CPU backend everywhere, on the CUDA backend where a GPU is.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/storage/memory_chunk_store.hpp"
#include "featsense/storage/shifting_map.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "featsense/tsdf/local_map_shift.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::storage {
namespace {

using tsdf::Index3;
using tsdf::Vec3;

constexpr double kMaxRange = 2.0;  // every ray, tau behind it included, stays in the small map
constexpr float kVoxel = 0.1f;
constexpr float kTruncation = 0.3f;
constexpr double kShiftThreshold = 0.8;

tsdf::TsdfSettings small_map_settings() {
  tsdf::TsdfSettings s;
  s.voxel_size_m = kVoxel;
  s.truncation_m = kTruncation;
  s.max_weight = 5.0f;
  s.map_size_m = {7.0f, 7.0f, 7.0f};  // 9 bricks = 7.2 m per axis
  s.interpolation_slope = static_cast<float>(std::tan(1.0 * M_PI / 180.0));
  return s;
}

tsdf::TsdfSettings large_map_settings() {
  tsdf::TsdfSettings s = small_map_settings();
  s.map_size_m = {16.0f, 16.0f, 12.0f};
  return s;
}

MapMetadata metadata() {
  MapMetadata m;
  m.voxel_size_m = kVoxel;
  m.truncation_m = kTruncation;
  m.max_weight = 5.0;
  m.sensor = "test";
  return m;
}

/// A closed room (floor z = 0, ceiling z = 3, walls at -1 and 7) with a ball in the middle,
/// seen from `origin` by a spherical grid of beams; hits beyond kMaxRange are dropped.
tsdf::RayBatch scan_from(const double origin[3]) {
  tsdf::RayBatch rays;
  rays.origins_m.push_back({static_cast<float>(origin[0]), static_cast<float>(origin[1]),
                            static_cast<float>(origin[2])});
  const double ball[3] = {3.0, 3.0, 1.5};
  const double ball_radius = 0.5;
  for (int row = 0; row < 24; ++row) {
    const double elevation = (-70.0 + 140.0 * row / 23.0) * M_PI / 180.0;
    for (int col = 0; col < 96; ++col) {
      const double azimuth = 2.0 * M_PI * (col + 0.37 * row) / 96.0;
      const double d[3] = {std::cos(elevation) * std::cos(azimuth),
                           std::cos(elevation) * std::sin(azimuth), std::sin(elevation)};
      double t = 1e9;
      for (int axis = 0; axis < 3; ++axis) {
        const double lo = axis == 2 ? 0.0 : -1.0;
        const double hi = axis == 2 ? 3.0 : 7.0;
        if (d[axis] > 1e-9) t = std::min(t, (hi - origin[axis]) / d[axis]);
        if (d[axis] < -1e-9) t = std::min(t, (lo - origin[axis]) / d[axis]);
      }
      const double oc[3] = {origin[0] - ball[0], origin[1] - ball[1], origin[2] - ball[2]};
      const double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
      const double disc =
          b * b - (oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - ball_radius * ball_radius);
      if (disc >= 0.0 && -b - std::sqrt(disc) > 0.0) t = std::min(t, -b - std::sqrt(disc));
      if (t > kMaxRange) continue;
      rays.endpoints_m.push_back({static_cast<float>(origin[0] + t * d[0]),
                                  static_cast<float>(origin[1] + t * d[1]),
                                  static_cast<float>(origin[2] + t * d[2])});
    }
  }
  return rays;
}

/// Sensor positions every 0.25 m along legs in +x, +y, +z, -x, -y, -z and +x again (back over
/// mapped space), around the ball.
std::vector<Vec3> sensor_path() {
  const double corners[][3] = {{0.2, 0.2, 1.0}, {5.8, 0.2, 1.0}, {5.8, 5.8, 1.0}, {5.8, 5.8, 2.2},
                               {0.2, 5.8, 2.2}, {0.2, 0.2, 2.2}, {0.2, 0.2, 1.0}, {5.8, 0.2, 1.0}};
  std::vector<Vec3> path;
  for (size_t leg = 0; leg + 1 < std::size(corners); ++leg) {
    const double* a = corners[leg];
    const double* b = corners[leg + 1];
    const double length = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    const int steps = static_cast<int>(std::ceil(length / 0.25));
    for (int s = 0; s < steps; ++s) {
      const double f = static_cast<double>(s) / steps;
      path.push_back({static_cast<float>(a[0] + f * (b[0] - a[0])),
                      static_cast<float>(a[1] + f * (b[1] - a[1])),
                      static_cast<float>(a[2] + f * (b[2] - a[2]))});
    }
  }
  return path;
}

std::unique_ptr<tsdf::Integrator> make_map(const std::string& backend,
                                           const tsdf::TsdfSettings& settings, Vec3 centre) {
  return backend == "cuda" ? tsdf::make_cuda_integrator(settings, centre)
                           : tsdf::make_cpu_integrator(settings, centre);
}

/// Maps the scans from path[first, last) with a shifting map into `store`, then syncs.
ShiftingMapStats map_into(ChunkStore& store, const std::string& backend,
                          const std::vector<Vec3>& path, size_t first, size_t last) {
  auto map = make_map(backend, small_map_settings(), path[first]);
  ShiftingMap shifting(*map, store, kShiftThreshold);
  for (size_t i = first; i < last; ++i) {
    shifting.follow(path[i]);
    const double origin[3] = {path[i].x, path[i].y, path[i].z};
    const tsdf::RayBatch rays = scan_from(origin);
    // The premise of the comparison: nothing of a ray falls outside the small map.
    const tsdf::LocalMapGeometry& g = map->geometry();
    for (const Vec3& p : rays.endpoints_m) {
      Index3 v;
      EXPECT_TRUE(g.voxel_in_map(p, v));
    }
    map->integrate(rays);
  }
  shifting.sync();
  return shifting.stats();
}

/// The reference: one large map around the whole path that never moves.
std::unique_ptr<tsdf::Integrator> map_without_shifting(const std::string& backend,
                                                       const std::vector<Vec3>& path) {
  auto map = make_map(backend, large_map_settings(), Vec3{3.0f, 3.0f, 1.5f});
  for (const Vec3& p : path) {
    const double origin[3] = {p.x, p.y, p.z};
    map->integrate(scan_from(origin));
  }
  return map;
}

/// Every voxel of `store` equals the reference map's: observed voxels the same bits, and no
/// voxel observed in one but not the other.
void expect_same_map(ChunkStore& store, const tsdf::Integrator& reference) {
  const tsdf::LocalMapGeometry& g = reference.geometry();
  const std::vector<uint32_t> voxels = reference.download();
  size_t reference_observed = 0;
  size_t differing = 0;
  std::map<ChunkKey, std::optional<Chunk>> chunks;
  for (int32_t z = g.origin.z; z < g.origin.z + g.dim.z; ++z) {
    for (int32_t y = g.origin.y; y < g.origin.y + g.dim.y; ++y) {
      for (int32_t x = g.origin.x; x < g.origin.x + g.dim.x; ++x) {
        const ChunkKey key = chunk_of_voxel(x, y, z);
        auto chunk = chunks.find(key);
        if (chunk == chunks.end()) chunk = chunks.emplace(key, store.read(key)).first;
        const uint32_t expected = voxels[g.linear({x, y, z})];
        const uint32_t actual =
            chunk->second ? chunk->second->at(x - key.x * kChunkSize, y - key.y * kChunkSize,
                                              z - key.z * kChunkSize)
                          : tsdf::kUnobservedVoxel;
        if (tsdf::unpack(expected).weight > 0) ++reference_observed;
        if (expected != actual) ++differing;
      }
    }
  }
  size_t store_observed = 0;
  for (const ChunkKey& key : store.keys()) {
    const std::optional<Chunk> stored = store.read(key);
    for (const uint32_t v : stored->voxels) store_observed += tsdf::unpack(v).weight > 0;
  }
  EXPECT_GT(reference_observed, 100000u);
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(store_observed, reference_observed) << "the store holds voxels the map never saw";
}

class ShiftingMapTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    std::string why;
    if (GetParam() == "cuda" && !tsdf::cuda_backend_available(&why)) {
      GTEST_SKIP() << "no GPU: " << why;
    }
  }
};

TEST_P(ShiftingMapTest, ShiftingManyTimesGivesTheMapOfOneLargeMap) {
  const std::vector<Vec3> path = sensor_path();
  MemoryChunkStore store(metadata());
  const ShiftingMapStats stats = map_into(store, GetParam(), path, 0, path.size());
  EXPECT_GE(stats.shifts, 12u);
  EXPECT_GT(stats.chunks_unchanged, 0u) << "the final sync rewrote chunks a shift had written";
  expect_same_map(store, *map_without_shifting(GetParam(), path));
}

TEST_P(ShiftingMapTest, ShiftingIntoAnHdf5StoreWithASmallCacheGivesTheSameMap) {
  const std::vector<Vec3> path = sensor_path();
  const auto dir = test::scratch_dir("shifting_map_" + GetParam());
  StoreSettings settings;
  settings.cache_bytes = 2 * kChunkBytes;  // chunks go to disk and come back
  settings.journal_limit_bytes = 64 << 10;
  {
    Hdf5ChunkStore store(dir / "map.h5", OpenMode::kCreate, metadata(), settings);
    map_into(store, GetParam(), path, 0, path.size());
    store.close();
  }
  Hdf5ChunkStore reopened(dir / "map.h5");
  expect_same_map(reopened, *map_without_shifting(GetParam(), path));
}

TEST_P(ShiftingMapTest, ContinuingFromAStoreGivesTheMapOfOneRun) {
  const std::vector<Vec3> path = sensor_path();
  MemoryChunkStore store(metadata());
  const size_t half = path.size() / 2;
  map_into(store, GetParam(), path, 0, half);
  // A new local map on the same store, as `featsense map --continue` makes.
  const ShiftingMapStats second = map_into(store, GetParam(), path, half, path.size());
  EXPECT_GT(second.bricks_loaded, 0u);
  expect_same_map(store, *map_without_shifting(GetParam(), path));
}

TEST_P(ShiftingMapTest, ABlockReadWhileMappingIsTheWholeMapsVoxels) {
  // Half-way along the path (never synced) the map lies partly in the local map, partly in the
  // store; a block read across both is the map of one large map at the same scans.
  std::vector<Vec3> path = sensor_path();
  path.resize(path.size() / 2);
  MemoryChunkStore store(metadata());
  auto map = make_map(GetParam(), small_map_settings(), path.front());
  ShiftingMap shifting(*map, store, kShiftThreshold);
  for (const Vec3& p : path) {
    shifting.follow(p);
    const double origin[3] = {p.x, p.y, p.z};
    map->integrate(scan_from(origin));
  }
  ASSERT_GE(shifting.stats().shifts, 4u);
  ASSERT_FALSE(store.keys().empty());
  const auto reference = map_without_shifting(GetParam(), path);
  const tsdf::LocalMapGeometry& g = reference->geometry();
  const std::vector<uint32_t> expected_all = reference->download();
  // An odd box, not aligned to bricks or chunks, reaching past the reference map on one side.
  const Index3 origin{g.origin.x + 3, g.origin.y - 5, g.origin.z + 7};
  const Index3 dim{g.dim.x - 1, g.dim.y - 11, g.dim.z - 9};
  std::vector<uint32_t> block;
  shifting.read_block(origin, dim, block);
  ASSERT_EQ(block.size(), static_cast<size_t>(dim.x) * dim.y * dim.z);
  size_t differing = 0;
  size_t observed = 0;
  for (int32_t z = 0; z < dim.z; ++z) {
    for (int32_t y = 0; y < dim.y; ++y) {
      for (int32_t x = 0; x < dim.x; ++x) {
        const Index3 v{origin.x + x, origin.y + y, origin.z + z};
        const uint32_t expected =
            g.contains(v) ? expected_all[g.linear(v)] : tsdf::kUnobservedVoxel;
        const uint32_t actual = block[x + dim.x * (y + static_cast<size_t>(dim.y) * z)];
        differing += expected != actual;
        observed += tsdf::unpack(actual).weight > 0;
      }
    }
  }
  EXPECT_GT(observed, 50000u);
  EXPECT_EQ(differing, 0u);

  // Several boxes at once (overlapping, one of them far outside) are each the box read alone;
  // vectors handed in are reused.
  const Index3 small{67, 67, 67};
  const std::vector<Index3> origins = {{g.origin.x + 10, g.origin.y + 20, g.origin.z + 3},
                                       {g.origin.x + 40, g.origin.y + 20, g.origin.z + 3},
                                       {g.origin.x - 500, g.origin.y, g.origin.z}};
  std::vector<std::vector<uint32_t>> blocks(1, std::vector<uint32_t>(7, 1u));
  shifting.read_blocks(origins, small, blocks);
  ASSERT_EQ(blocks.size(), origins.size());
  for (size_t i = 0; i < origins.size(); ++i) {
    std::vector<uint32_t> alone;
    shifting.read_block(origins[i], small, alone);
    EXPECT_EQ(blocks[i], alone) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, ShiftingMapTest, ::testing::Values("cpu", "cuda"));

TEST(ShiftingMap, MovingFarAwayAndBackLosesNothing) {
  MemoryChunkStore store(metadata());
  auto map = tsdf::make_cpu_integrator(small_map_settings(), Vec3{0, 0, 1});
  ShiftingMap shifting(*map, store, kShiftThreshold);
  const double origin[3] = {0.2, 0.2, 1.0};
  map->integrate(scan_from(origin));
  const std::vector<uint32_t> before = map->download();
  const Index3 home = map->geometry().origin;
  shifting.move_to({home.x + 800, home.y - 808, home.z + 8});  // no brick in common
  EXPECT_FALSE(store.keys().empty());
  for (const uint32_t v : map->download()) ASSERT_EQ(v, tsdf::kUnobservedVoxel);
  shifting.move_to(home);
  EXPECT_EQ(map->download(), before);
}

/// A store that fails on request: its reads, its writes or both throw, as a full disk or a
/// damaged file would make them.
class FailingStore final : public ChunkStore {
 public:
  explicit FailingStore(ChunkStore& inner) : inner_(inner) {}
  bool fail_reads = false;
  bool fail_writes = false;
  std::optional<Chunk> read(const ChunkKey& key) override {
    if (fail_reads) throw std::runtime_error("read failed");
    return inner_.read(key);
  }
  void write(const ChunkKey& key, const Chunk& chunk) override {
    if (fail_writes) throw std::runtime_error("write failed");
    inner_.write(key, chunk);
  }
  std::vector<ChunkKey> keys() const override { return inner_.keys(); }
  void flush() override { inner_.flush(); }
  const MapMetadata& metadata() const override { return inner_.metadata(); }

 private:
  ChunkStore& inner_;
};

TEST(ShiftingMap, AShiftThatCannotReachTheStoreLeavesTheMapWholeWhereItWas) {
  MemoryChunkStore memory(metadata());
  FailingStore store(memory);
  auto map = tsdf::make_cpu_integrator(small_map_settings(), Vec3{0, 0, 1});
  ShiftingMap shifting(*map, store, kShiftThreshold);
  const double origin[3] = {0.2, 0.2, 1.0};
  map->integrate(scan_from(origin));
  // The wall at x = -1 goes into the store ...
  shifting.move_to(
      {map->geometry().origin.x + 24, map->geometry().origin.y, map->geometry().origin.z});
  ASSERT_FALSE(memory.keys().empty());
  map->integrate(scan_from(origin));
  const std::vector<uint32_t> before = map->download();
  const Index3 home = map->geometry().origin;
  // ... and comes back, while the wall at y = -1 leaves.
  const Index3 away = {home.x - 24, home.y + 24, home.z};
  for (const bool reads : {true, false}) {
    store.fail_reads = reads;
    store.fail_writes = !reads;
    EXPECT_THROW(shifting.move_to(away), std::runtime_error);
    EXPECT_EQ(map->geometry().origin.x, home.x);
    EXPECT_EQ(map->geometry().origin.y, home.y);
    EXPECT_EQ(map->download(), before);
  }
  // Once the store works again the same shift and the way back lose nothing.
  store.fail_reads = store.fail_writes = false;
  EXPECT_TRUE(shifting.move_to(away));
  EXPECT_TRUE(shifting.move_to(home));
  EXPECT_EQ(map->download(), before);
}

/// An integrator that passes everything on and counts how much of the map is copied out at
/// once.
class CopyCountingMap final : public tsdf::Integrator {
 public:
  explicit CopyCountingMap(tsdf::Integrator& inner) : inner_(inner) {}
  size_t most_bricks_read = 0;
  size_t reads = 0;
  size_t downloads = 0;
  std::string backend_name() const override { return inner_.backend_name(); }
  tsdf::IntegrationStats integrate(const tsdf::RayBatch& rays) override {
    return inner_.integrate(rays);
  }
  const tsdf::LocalMapGeometry& geometry() const override { return inner_.geometry(); }
  std::vector<uint32_t> download() const override {
    ++const_cast<CopyCountingMap*>(this)->downloads;
    return inner_.download();
  }
  size_t memory_bytes() const override { return inner_.memory_bytes(); }
  void read_bricks(const std::vector<Index3>& bricks,
                   std::vector<uint32_t>& voxels) const override {
    auto* self = const_cast<CopyCountingMap*>(this);
    self->most_bricks_read = std::max(most_bricks_read, bricks.size());
    ++self->reads;
    inner_.read_bricks(bricks, voxels);
  }
  void write_bricks(const std::vector<Index3>& bricks,
                    const std::vector<uint32_t>& voxels) override {
    inner_.write_bricks(bricks, voxels);
  }
  void set_origin(Index3 origin) override { inner_.set_origin(origin); }

 private:
  tsdf::Integrator& inner_;
};

TEST(ShiftingMap, ASyncCopiesTheMapOutABatchOfChunksAtATime) {
  // About 30 x 30 x 12 m in voxels of 0.1 m: 75 chunks of 64^3 voxels or more, more than
  // two batches of 32.
  tsdf::TsdfSettings settings = large_map_settings();
  settings.map_size_m = {30.0f, 30.0f, 12.0f};
  MemoryChunkStore store(metadata());
  auto inner = tsdf::make_cpu_integrator(settings, Vec3{3, 3, 1.5});
  CopyCountingMap map(*inner);
  ShiftingMap shifting(map, store, kShiftThreshold);
  for (const Vec3& p : sensor_path()) {
    const double at[3] = {p.x, p.y, p.z};
    map.integrate(scan_from(at));
  }
  shifting.sync();
  EXPECT_EQ(map.downloads, 0u);
  EXPECT_GT(map.reads, 2u);
  EXPECT_LE(map.most_bricks_read, size_t{32} * 512);  // 32 chunks of 8^3 bricks
  EXPECT_LT(map.most_bricks_read, tsdf::bricks_of(map.geometry()).size());
  expect_same_map(store, *inner);
}

TEST(ShiftingMap, ExchangedBricksAreTheSymmetricDifference) {
  tsdf::LocalMapGeometry from;
  from.dim = {24, 24, 24};
  from.origin = {-8, 0, 8};
  tsdf::LocalMapGeometry to = from;
  to.origin = {0, -16, 8};
  const tsdf::BrickExchange exchange = tsdf::exchanged_bricks(from, to);
  // 27 bricks each; the boxes share x in {0, 1} and y in {0} -> 2 * 1 * 3 = 6 bricks.
  EXPECT_EQ(exchange.leaving.size(), 21u);
  EXPECT_EQ(exchange.entering.size(), 21u);
  for (const Index3& b : exchange.leaving) EXPECT_FALSE(to.contains_brick(b));
  for (const Index3& b : exchange.entering) EXPECT_FALSE(from.contains_brick(b));
}

TEST(ShiftingMap, AStoreOfAnotherVoxelSizeIsRefused) {
  MapMetadata other = metadata();
  other.voxel_size_m = 0.05;
  MemoryChunkStore store(other);
  auto map = tsdf::make_cpu_integrator(small_map_settings(), Vec3{});
  EXPECT_THROW(ShiftingMap(*map, store, kShiftThreshold), std::invalid_argument);
}

TEST(ShiftingMap, BrickAccessOutsideTheMapIsAnError) {
  auto map = tsdf::make_cpu_integrator(small_map_settings(), Vec3{});
  std::vector<uint32_t> voxels;
  EXPECT_THROW(map->read_bricks({Index3{100, 0, 0}}, voxels), std::out_of_range);
  EXPECT_THROW(map->write_bricks({Index3{0, 0, 0}}, std::vector<uint32_t>(3)),
               std::invalid_argument);
  EXPECT_THROW(map->set_origin({3, 0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace featsense::storage
