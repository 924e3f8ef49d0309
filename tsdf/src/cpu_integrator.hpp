#pragma once
// The CPU integrator (make_cpu_integrator): the map, the scan's candidates and bits, and the
// sectors that share the map out among the threads. Its jobs lie in three files:
//   cpu_integrator.cpp  a scan's phases in order, the rays to walk, the brick access;
//   cpu_sectors.cpp     the sectors: who owns which bricks, the walks, what is handed over;
//   cpu_fusion.cpp      the fusion of the bricks a scan listed.
// Its accelerators (free space eight rays at a time, the word table, the free-space fusion,
// huge pages) lie in cpu_fast/.

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "cpu_fast/free_space_lanes.hpp"
#include "cpu_fast/free_word_cache.hpp"
#include "cpu_fast/huge_page_allocator.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "featsense/tsdf/voxel.hpp"
#include "ray_marcher.hpp"

namespace featsense::tsdf::detail {

class CpuIntegrator final : public Integrator {
 public:
  CpuIntegrator(const TsdfSettings& settings, Vec3 centre_m);

  std::string backend_name() const override { return "cpu"; }
  const LocalMapGeometry& geometry() const override { return geometry_; }
  std::vector<uint32_t> download() const override { return {map_.begin(), map_.end()}; }
  size_t memory_bytes() const override {
    return geometry_.voxel_count() * 2 * sizeof(uint32_t) + 3 * geometry_.voxel_count() / 8 +
           3 * geometry_.voxel_count() / kBrickVoxels;
  }
  void read_bricks(const std::vector<Index3>& bricks, std::vector<uint32_t>& voxels) const override;
  void write_bricks(const std::vector<Index3>& bricks,
                    const std::vector<uint32_t>& voxels) override;
  void set_origin(Index3 origin) override;
  IntegrationStats integrate(const RayBatch& rays) override;

 private:
  // Sectors differ in work (the real OS1-128 frames: 9.7 to 22.5 ms a sector of eight): with
  // eight a thread instead of four, two threads finished their walks 4 ms sooner, for 0.3 ms
  // more of candidates handed over (test/bench/RESULTS.md).
  static constexpr int kSectorsPerThread = 8;
  static constexpr size_t kWordsPerBrick = kBrickVoxels / 64;

  /// A candidate for a voxel of another sector.
  struct HandedOver {
    size_t index;
    uint32_t key;
  };
  /// Free space passed in a 64-voxel word of another sector.
  struct FreeBits {
    size_t word;
    uint64_t bits;
  };
  /// What one sector's task collects while walking its rays.
  struct Part {
    std::vector<uint32_t> touched;                        ///< bricks listed for the fusion
    std::vector<std::vector<HandedOver>> handed_over;     ///< by owning sector
    std::vector<std::vector<FreeBits>> free_handed_over;  ///< by owning sector
    std::vector<FreeWalk> free_walks;                     ///< set aside for the lanes
    FreeSpaceLanes lanes;                                 ///< which walk them
    FreeWordCache word_cache;                             ///< what they pass, merged
  };

  // cpu_integrator.cpp
  /// Calls visit(k, storage offset of bricks[k]) for every brick, in parallel.
  template <typename Visit>
  void for_each_brick(const std::vector<Index3>& bricks, const Visit& visit) const;
  /// Indices of the rays to march: all, or the first end point of each voxel of the local
  /// map plus every end point outside it (the rule of TsdfSettings::reduce_points_per_voxel,
  /// computed as the CUDA backend does: a minimum of point indices per voxel).
  std::vector<uint32_t> rays_to_march(const RayBatch& rays);

  // cpu_sectors.cpp
  struct SectorVisitor;
  /// Sectors per thread: enough for the threads to balance their load, few enough that
  /// little is handed over between sectors near the sensor.
  static size_t sector_count();
  /// The sector of map-frame direction (dx, dy) from the sensor.
  size_t sector_of(float dx, float dy) const;
  /// Gives each brick column of the map to the sector of its centre seen from `centre`.
  void assign_brick_owners(Vec3 centre);
  /// The rays to march, by the sector of their end point.
  std::vector<std::vector<uint32_t>> rays_by_sector(const RayBatch& rays,
                                                    const std::vector<uint32_t>& kept,
                                                    Vec3 centre) const;
  /// Sector p walks its rays: candidates for its own voxels are written, the others handed over.
  void march_sector(size_t p, const RayBatch& rays, const std::vector<uint32_t>& ray_ids,
                    const RayMarchParams& params);
  /// Sector p applies what the other sectors handed over to it.
  void take_over(size_t p);
  void propose(size_t p, size_t index, int32_t value, bool interpolated);
  void pass_free_space(Part& part, size_t word, uint64_t bits);
  void list_brick(Part& part, size_t brick);
  void lower(Part& part, size_t index, uint32_t key, uint32_t current);

  // cpu_fusion.cpp
  /// Fuses the candidates of the listed bricks into the map, resets them, and returns how
  /// many voxels were updated.
  size_t fuse(const std::vector<uint32_t>& bricks);
  static constexpr size_t kVoxelsPerLine = 64 / sizeof(uint32_t);
  void prefetch_bits(size_t brick) const;
  void prefetch_voxels(size_t brick) const;
  void prefetch_candidates(size_t brick) const;
  size_t fuse_brick(size_t brick, int32_t falloff, uint32_t max_weight);

  /// Marks the brick whose voxels are all settled free space, for the walk to jump across.
  void note_settled_brick(size_t brick) {
    uint64_t all = ~uint64_t{0};
    for (size_t word = brick * kWordsPerBrick; word < (brick + 1) * kWordsPerBrick; ++word) {
      all &= settled_[word];
    }
    settled_bricks_[brick] = all == ~uint64_t{0} ? 1 : 0;
  }

  TsdfSettings settings_;
  LocalMapGeometry geometry_;
  template <typename T>
  using LargeArray = std::vector<T, HugePageAllocator<T>>;
  LargeArray<uint32_t> map_;
  /// The scan's candidates. Atomic only so that a sector may read a voxel another one writes
  /// (to drop moot candidates); every access is relaxed, plain loads and stores.
  LargeArray<std::atomic<uint32_t>> candidates_;
  std::vector<uint8_t> brick_owner_;     ///< the sector that writes each brick, this scan
  std::vector<uint8_t> brick_listed_;    ///< 1 while a brick is listed for the fusion
  LargeArray<uint64_t> occupancy_;       ///< a bit per voxel that has a candidate
  LargeArray<uint64_t> free_space_;      ///< a bit per voxel passed in free space this scan
  LargeArray<uint64_t> settled_;         ///< a bit per voxel of settled free space
  std::vector<uint8_t> settled_bricks_;  ///< 1 per brick of settled free space only
  uint32_t settled_voxel_;               ///< what such a voxel holds
  std::vector<Part> parts_;              ///< one per sector
  FreeSpaceMap free_map_{};              ///< the map as free-space walks see it, this scan
  const bool lanes_supported_ = FreeSpaceLanes::supported();
};

}  // namespace featsense::tsdf::detail
