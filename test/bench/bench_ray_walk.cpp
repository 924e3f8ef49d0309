// The walk of the CPU integrator's rays on one thread, apart from the rest of a scan (sectors,
// memory of the map, fusion): the first scan of the built-in box room (an OS1-128, 1024 x 128
// rays, in a 20 x 20 x 4 m room; test::box_room_rays), in the default 40 x 40 x 15 m map at
// 6.4 cm centred on the sensor, every ray carving all the way (no sparse carving). Most of a
// real scan's walking is free space, which the CPU integrator takes a 64-voxel word at a time:
//   bench_ray_walk --benchmark_filter=Words    the scalar loop (free_space_walk.hpp)
//   bench_ray_walk --benchmark_filter=Lanes    eight walks at a time, as the integrator runs
//                                              them where the processor has AVX2
//                                              (free_space_lanes.hpp)
//   bench_ray_walk --benchmark_filter=Voxels   every voxel handed over on its own
// Figures: test/bench/RESULTS.md.

#include <benchmark/benchmark.h>

#include <type_traits>
#include <vector>

#include "cpu_fast/free_space_lanes.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"
#include "ray_walk.hpp"
#include "tsdf/box_room_rays.hpp"

namespace featsense::tsdf {
namespace {

/// Takes every candidate, free space as words: what the walk hands over, folded into one
/// value so that nothing is optimised away. The free space at the end of each walk is walked
/// at once by the scalar loop.
struct WordSink {
  static constexpr bool kTakesFreeWalks = true;
  detail::FreeSpaceMap map{};
  uint64_t folded = 0;
  size_t words = 0;
  void operator()(size_t index, int32_t value, bool interpolated) {
    folded += index * 31u + static_cast<uint32_t>(value) + (interpolated ? 1u : 0u);
  }
  void free_walk(const detail::FreeWalk& walk) {
    detail::walk_free_space_job(walk, map, nullptr, *this);
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
  std::vector<detail::FreeWalk> walks;
  void free_walk(const detail::FreeWalk& walk) { walks.push_back(walk); }
};

template <typename Sink>
void walk_scan(benchmark::State& state) {
  const TsdfSettings settings;
  const RayBatch scan = test::box_room_rays(1, false).front();
  const LocalMapGeometry map = centred_geometry(settings, scan.origin(0));
  detail::RayMarchParams params;
  params.truncation_m = settings.truncation_m;
  for (auto _ : state) {
    Sink sink;
    if constexpr (std::is_base_of_v<WordSink, Sink>) sink.map = detail::FreeSpaceMap::of(map);
    for (size_t i = 0; i < scan.size(); ++i)
      detail::walk_ray(scan.origin(i), scan.endpoints_m[i], map, params, sink);
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
    for (size_t i = 0; i < scan.size(); ++i)
      detail::walk_ray(scan.origin(i), scan.endpoints_m[i], map, params, sink);
    double turns = 0;
    for (const detail::FreeWalk& walk : sink.walks) turns += walk.turns;
    state.counters["free_walks"] = static_cast<double>(sink.walks.size());
    state.counters["free_voxels"] = turns;
  }
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(scan.size()),
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
