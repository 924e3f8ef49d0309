// The walk of the CPU integrator's rays on one thread, apart from the rest of a scan (sectors,
// memory of the map, fusion): an OS1-128-like scan (1024 x 128 rays, +/-22.5 deg) from near
// the centre of a 34 x 20 x 7.5 m box room, in the default 40 x 40 x 15 m map at 6.4 cm,
// every ray carving all the way (no sparse carving). Most of a real scan's walking is free
// space, which the CPU integrator takes a 64-voxel word at a time (free_space_walk.hpp):
//   bench_ray_walk --benchmark_filter=Words    that path, as the integrator runs it
//   bench_ray_walk --benchmark_filter=Voxels   every voxel handed over on its own
// Figures: test/bench/RESULTS.md.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <utility>
#include <vector>

#include "featsense/tsdf/tsdf_settings.hpp"
#include "free_space_lanes.hpp"
#include "ray_walk.hpp"

namespace featsense::tsdf {
namespace {

/// Rays of an OS1-128 at (0.01, 0.02, 0.03) to the walls, floor and ceiling of a box room.
std::vector<std::pair<Vec3, Vec3>> box_room_scan() {
  constexpr int kBeams = 128;
  constexpr int kColumns = 1024;
  constexpr float kPi = 3.14159265f;
  const Vec3 origin{0.01f, 0.02f, 0.03f};
  const float low[3] = {-15.0f, -12.0f, -1.5f};
  const float high[3] = {19.0f, 8.0f, 6.0f};
  std::vector<std::pair<Vec3, Vec3>> rays;
  for (int beam = 0; beam < kBeams; ++beam) {
    const float elevation = (-22.5f + 45.0f * static_cast<float>(beam) / (kBeams - 1)) * kPi / 180;
    for (int column = 0; column < kColumns; ++column) {
      const float azimuth = 2.0f * kPi * static_cast<float>(column) / kColumns;
      const float d[3] = {std::cos(elevation) * std::cos(azimuth),
                          std::cos(elevation) * std::sin(azimuth), std::sin(elevation)};
      float range = 1e9f;
      for (int axis = 0; axis < 3; ++axis) {
        const float o = axis == 0 ? origin.x : axis == 1 ? origin.y : origin.z;
        if (d[axis] > 0.0f) range = std::min(range, (high[axis] - o) / d[axis]);
        if (d[axis] < 0.0f) range = std::min(range, (low[axis] - o) / d[axis]);
      }
      rays.emplace_back(origin, origin + range * Vec3{d[0], d[1], d[2]});
    }
  }
  return rays;
}

/// Takes every candidate, free space as words: what the walk hands over, folded into one
/// value so that nothing is optimised away.
struct WordSink {
  static constexpr bool kTakesFreeWords = true;
  uint64_t folded = 0;
  size_t words = 0;
  void operator()(size_t index, int32_t value, bool interpolated) {
    folded += index * 31u + static_cast<uint32_t>(value) + (interpolated ? 1u : 0u);
  }
  void free_word(size_t word, uint64_t bits) {
    folded ^= word * 0x9E3779B97F4A7C15ull + bits;
    ++words;
  }
};

/// The same without free words: every voxel through operator().
struct VoxelSink {
  uint64_t folded = 0;
  void operator()(size_t index, int32_t value, bool interpolated) {
    folded += index * 31u + static_cast<uint32_t>(value) + (interpolated ? 1u : 0u);
  }
};

/// The same, the free space of the walks set aside and walked eight at a time.
struct LaneSink : WordSink {
  static constexpr bool kTakesFreeWalks = true;
  std::vector<detail::FreeWalk> walks;
  void free_walk(const detail::FreeWalk& walk) { walks.push_back(walk); }
};

template <typename Sink>
void walk_scan(benchmark::State& state) {
  const TsdfSettings settings;
  const LocalMapGeometry map = centred_geometry(settings, Vec3{0.0f, 0.0f, 0.0f});
  const std::vector<std::pair<Vec3, Vec3>> rays = box_room_scan();
  detail::RayMarchParams params;
  params.truncation_m = settings.truncation_m;
  for (auto _ : state) {
    Sink sink;
    for (const auto& [origin, endpoint] : rays)
      detail::walk_ray(origin, endpoint, map, params, sink);
    if constexpr (std::is_same_v<Sink, LaneSink>) {
      detail::FreeSpaceLanes lanes;
      lanes.start(sink.walks.data(), sink.walks.size(), detail::FreeSpaceMap::of(map));
      bool more = true;
      while (more) {
        more = lanes.walk();
        for (size_t k = 0; k < lanes.words(); ++k) sink.free_word(lanes.word(k), lanes.bits(k));
      }
    }
    benchmark::DoNotOptimize(sink.folded);
  }
  if constexpr (std::is_same_v<Sink, LaneSink>) {
    Sink sink;
    for (const auto& [origin, endpoint] : rays)
      detail::walk_ray(origin, endpoint, map, params, sink);
    double turns = 0;
    for (const detail::FreeWalk& walk : sink.walks) turns += walk.turns;
    state.counters["free_walks"] = static_cast<double>(sink.walks.size());
    state.counters["free_voxels"] = turns;
  }
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(rays.size()),
                                                benchmark::Counter::kIsIterationInvariantRate);
}

void Words(benchmark::State& state) { walk_scan<WordSink>(state); }
void Voxels(benchmark::State& state) { walk_scan<VoxelSink>(state); }
void Lanes(benchmark::State& state) { walk_scan<LaneSink>(state); }
BENCHMARK(Words)->Unit(benchmark::kMillisecond);
BENCHMARK(Voxels)->Unit(benchmark::kMillisecond);
BENCHMARK(Lanes)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace featsense::tsdf

BENCHMARK_MAIN();
