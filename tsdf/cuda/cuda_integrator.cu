// The CUDA integrator: the same rule as the CPU reference (voxel.hpp, ray_walk.hpp) in
// six kernels per scan: keep one end point per voxel (two), the per-scan minimum (atomicMin
// on the ordered candidate keys; free space, whose key is always +tau, as a bit per voxel),
// the lists of touched bricks (with candidates, and only passed in free space), and the
// fusion of each list's voxels with the reset of the candidates and bits. Free-space
// candidates pass settled free space by (voxel.hpp, settled_free_voxel), found in a bit per
// voxel that the fusion keeps.

#include <cuda_runtime.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "brick_checks.hpp"
#include "cuda_check.hpp"
#include "device_buffer.hpp"
#include "featsense/tsdf/host_memory.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "parallel_copy.hpp"
#include "ray_walk.hpp"

namespace featsense::tsdf {
namespace {

constexpr int kThreads = 256;

unsigned int blocks_for(size_t n) {
  return static_cast<unsigned int>((n + kThreads - 1) / kThreads);
}

/// Phase 1 of the reduction: per voxel of the local map, the smallest index of an end point.
__global__ void mark_first_point_kernel(const Vec3* endpoints, uint32_t n, LocalMapGeometry map,
                                        uint32_t* candidates) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  Index3 v;
  if (map.voxel_in_map(endpoints[i], v)) atomicMin(&candidates[map.linear(v)], i);
}

/// Phase 2: the rays to march (the first point of each voxel, every point outside the map),
/// and the voxels' slots reset for the candidates.
__global__ void select_rays_kernel(const Vec3* endpoints, uint32_t n, LocalMapGeometry map,
                                   uint32_t* candidates, uint32_t* kept, uint32_t* kept_count) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  Index3 v;
  bool keep = true;
  if (map.voxel_in_map(endpoints[i], v)) {
    uint32_t* slot = &candidates[map.linear(v)];
    keep = *slot == i;
    // The winner resets the slot at once: a loser reading it afterwards sees
    // kEmptyCandidate, which is no point index, so it still loses.
    if (keep) *slot = kEmptyCandidate;
  }
  if (keep) kept[atomicAdd(kept_count, 1u)] = i;
}

/// Sets each lane's voxel bit in a bit set of 32-bit words (the settled bits), where a warp's
/// 32 consecutive voxels are a word, and returns the word. The whole warp calls it, on 32
/// consecutive voxels starting at a multiple of 32.
__device__ uint32_t write_warp_bits(uint32_t* bits, size_t index, bool bit) {
  const uint32_t word = __ballot_sync(0xffffffffu, bit);
  if (threadIdx.x % 32u == 0u) bits[index / 32] = word;
  return word;
}

struct ProposeCandidate {
  LocalMapGeometry map;
  uint32_t* candidates;
  uint32_t* brick_flags;
  uint32_t* band_bricks;  ///< 1 per brick with a candidate this scan (not free space alone)
  const uint32_t* settled;
  uint32_t* free_space;  ///< a bit per voxel that a ray passed in free space this scan

  __device__ void operator()(uint32_t index, int32_t value, bool interpolated) const {
    // Both loads are issued before either is needed, so the walk waits for memory once per
    // voxel, not twice. Keys only decrease during a scan, so a stale read can only cause an
    // unneeded atomic.
    const uint32_t current = candidates[index];
    const uint32_t settled_word =
        passes_settled_by(value, interpolated) ? __ldg(&settled[index / 32]) : 0u;
    // Settled free space stays as it is (its bits are mostly in the L1 cache).
    if (((settled_word >> (index % 32)) & 1u) != 0u) return;
    const uint32_t key = make_candidate(value, interpolated);
    if (current <= key) return;
    // The old value is not needed, so the minimum is a reduction the thread does not wait for.
    atomicMin(&candidates[index], key);
    // Mark the brick for the fusion. The thread whose minimum lands first on an empty voxel
    // read it empty (nothing had landed before), so every touched brick gets marked.
    if (current == kEmptyCandidate) {
      brick_flags[index / kBrickVoxels] = 1u;
      band_bricks[index / kBrickVoxels] = 1u;
    }
  }
};

/// A thread's visitor: free space goes to a bit per voxel, the rest to ProposeCandidate.
/// Free space is most of a walk, and every free-space visit proposes the same key (+tau,
/// measured), so the scan's minimum only needs to know which voxels were passed: the fusion
/// takes min(candidate, +tau) where the bit is set, the same as if each visit had been an
/// atomicMin. The bits of the voxels in one 32-bit word (4 x 8 voxels of a brick) are
/// gathered while the walk stays in that word and then set with one atomicOr that the thread
/// does not wait for, so a free-space step waits for no memory at all (a candidate waits for
/// its key's load). Settled free space is left out: its bits, loaded on entering a word, are
/// cleared before the atomicOr.
struct WalkVisitor {
  const ProposeCandidate& propose;
  uint32_t word = 0xFFFFFFFFu;  // the word being gathered, none yet
  uint32_t bits = 0;
  uint32_t settled_word = 0;
  uint32_t marked_brick = 0xFFFFFFFFu;  // the brick this walk last marked for the fusion

  __device__ void operator()(uint32_t index, int32_t value, bool interpolated) {
    if (value != kValueScale || interpolated) {
      propose(index, value, interpolated);
      return;
    }
    const uint32_t w = index / 32;
    if (w != word) {
      flush();
      word = w;
      settled_word = __ldg(&propose.settled[w]);
    }
    bits |= 1u << (index % 32);
  }

  __device__ void flush() {
    const uint32_t fresh = bits & ~settled_word;
    bits = 0;
    if (fresh == 0u) return;
    atomicOr(&propose.free_space[word], fresh);
    // A brick's flag stays set until the fusion: once a walk has set it, it need not again
    // (most flushes stay in the brick of the last one).
    const uint32_t brick = word / (kBrickVoxels / 32);
    if (brick != marked_brick) {
      propose.brick_flags[brick] = 1u;
      marked_brick = brick;
    }
  }
};

/// Appends the calling lanes' items to a list, one atomic per warp (in no particular order).
__device__ void append_warp_items(bool take, uint32_t item, uint32_t* list, uint32_t* count) {
  const unsigned int lanes = __ballot_sync(0xffffffffu, take);
  if (lanes == 0u) return;
  const int lane = static_cast<int>(threadIdx.x % 32u);
  const int leader = __ffs(static_cast<int>(lanes)) - 1;
  uint32_t first = 0;
  if (lane == leader) first = atomicAdd(count, static_cast<uint32_t>(__popc(lanes)));
  first = __shfl_sync(0xffffffffu, first, leader);
  if (take) list[first + __popc(lanes & ((1u << lane) - 1u))] = item;
}

/// The marked bricks, listed for the fusion: those with a candidate, and those only passed in
/// free space (most of them), which the fusion treats apart.
__global__ void list_touched_bricks_kernel(const uint32_t* brick_flags, const uint32_t* band_bricks,
                                           uint32_t brick_count, uint32_t* band_list,
                                           uint32_t* band_count, uint32_t* free_list,
                                           uint32_t* free_count) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const bool touched = i < brick_count && brick_flags[i] != 0u;
  const bool band = touched && band_bricks[i] != 0u;
  append_warp_items(band, i, band_list, band_count);
  append_warp_items(touched && !band, i, free_list, free_count);
}

/// Parts each ray's walk is cut into (ray_walk.hpp, WalkPart). Walks differ in length by 100x
/// and a block's take as long as its longest, so with one block a ray's whole walk, some
/// multiprocessors finished in 60 % of the time of the last (a scan's blocks fit on the GPU
/// at once, so none were left to give them). In parts, the blocks are shorter and a second
/// wave of them fills the multiprocessors that finish first.
constexpr int32_t kWalkParts = 6;
constexpr float kWalkPartLength = 4.0f;  ///< metres

/// Threads a block of the walk: blocks of 128 rather than 256 end sooner, so the second wave's
/// blocks find room on the multiprocessors that finish first earlier (a scan's walk 270 ->
/// 260 µs on an H100).
constexpr unsigned int kWalkThreads = 128;

// At most 64 registers, so that 32 warps share a multiprocessor. (A walk without the limit
// takes 78 registers.)
__global__ void __launch_bounds__(kWalkThreads, 8)
    min_tsdf_kernel(const Vec3* origins, bool origin_per_point, const Vec3* endpoints,
                    const uint8_t* interpolate, const uint8_t* carving_level, bool carve_free_space,
                    float dense_range_m, const uint32_t* kept, const uint32_t* kept_count,
                    detail::RayMarchParams params, ProposeCandidate propose,
                    const uint8_t* settled_bricks) {
  // Block b walks part b % kWalkParts of the rays of block b / kWalkParts: the parts of a
  // ray are walked at about the same time, by neighbouring blocks.
  const uint32_t k = blockIdx.x / static_cast<uint32_t>(kWalkParts) * blockDim.x + threadIdx.x;
  if (k >= *kept_count) return;
  const uint32_t i = kept[k];
  const Vec3 origin = origins[origin_per_point ? i : 0];
  // A ray is cut into one part per kWalkPartLength of its length, at most kWalkParts: the
  // shorter ones need not pay for setting up parts they hardly need.
  const float length = norm(endpoints[i] - origin);
  const float wanted = length / kWalkPartLength;
  const int32_t count =
      wanted < static_cast<float>(kWalkParts) ? 1 + static_cast<int32_t>(wanted) : kWalkParts;
  const detail::WalkPart part{static_cast<int32_t>(blockIdx.x % static_cast<uint32_t>(kWalkParts)),
                              count};
  if (part.index >= part.count) return;
  detail::RayMarchParams ray = params;
  if (interpolate != nullptr && interpolate[i] == 0) ray.interpolation_slope = 0.0f;
  ray.carve_from_m =
      detail::carving_start(carve_free_space, dense_range_m,
                            carving_level == nullptr ? kFullCarvingLevel : carving_level[i]);
  WalkVisitor visit{propose};
  detail::walk_ray(origin, endpoints[i], propose.map, ray, visit, settled_bricks, part);
  visit.flush();
}

/// A brick's voxels as a warp fuses them: 16 rounds of 32 consecutive voxels, lane l taking
/// voxel 32 r + l of round r.
constexpr int kFuseRounds = kBrickVoxels / 32;

/// One warp per brick that was only passed in free space (no candidate): fuses +tau,
/// measured, into the voxels whose bit is set (none of them settled: the walks leave settled
/// voxels out), resets the bits and the brick's flag, and renews its settled bits and flag.
/// Rounds without a bit are skipped (the whole warp sees the same word) and keep their settled
/// bits. A kernel of its own: without keys it needs half the registers of the other bricks'
/// fusion, and the code of neither slows the other.
__global__ void __launch_bounds__(kThreads, 4)
    fuse_free_bricks_kernel(const uint32_t* __restrict__ free_bricks,
                            const uint32_t* __restrict__ free_count,
                            uint32_t* __restrict__ brick_flags, uint32_t* __restrict__ map,
                            uint32_t* __restrict__ settled, uint32_t* __restrict__ free_space,
                            uint8_t* __restrict__ settled_bricks, int32_t falloff,
                            uint32_t max_weight, uint32_t* __restrict__ voxels_updated) {
  const uint32_t count = *free_count;
  const uint32_t settled_voxel = settled_free_voxel(max_weight);
  const uint32_t free_weight = candidate_weight(kValueScale, falloff);
  const uint32_t lane = threadIdx.x % 32u;
  const uint32_t warps = gridDim.x * blockDim.x / 32u;
  uint32_t updated = 0;  // lane 0's count over its bricks
  // A warp's bricks pass through a pipeline, so that its three waits for memory overlap: while
  // one brick's voxels are fused, the next one's bit words and the index of the one after are
  // on their way (otherwise each brick waits for its index, then its words, then its voxels).
  const bool word_lane = lane < static_cast<uint32_t>(kFuseRounds);
  const auto brick_at = [&](uint32_t k) { return k < count ? free_bricks[k] : 0u; };
  const auto word_of = [&](const uint32_t* bits, uint32_t k, uint32_t brick) {
    return k < count && word_lane ? bits[static_cast<size_t>(brick) * (kBrickVoxels / 32) + lane]
                                  : 0u;
  };
  uint32_t k = (blockIdx.x * blockDim.x + threadIdx.x) / 32u;
  uint32_t brick = brick_at(k);
  uint32_t settled_word = word_of(settled, k, brick);
  uint32_t free_word = word_of(free_space, k, brick);
  uint32_t next_brick = brick_at(k + warps);
  for (; k < count; k += warps) {
    const uint32_t next_settled = word_of(settled, k + warps, next_brick);
    const uint32_t next_free = word_of(free_space, k + warps, next_brick);
    const uint32_t brick_after = brick_at(k + 2 * warps);
    const size_t first = static_cast<size_t>(brick) * kBrickVoxels;
    if (free_word != 0u) free_space[first / 32 + lane] = 0u;
    uint32_t voxels[kFuseRounds];
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      const bool passed = ((__shfl_sync(0xffffffffu, free_word, r) >> lane) & 1u) != 0u;
      voxels[r] = passed ? map[first + r * 32 + lane] : 0u;
    }
    bool all_settled = true;
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      const uint32_t passed_word = __shfl_sync(0xffffffffu, free_word, r);
      uint32_t word = __shfl_sync(0xffffffffu, settled_word, r);
      if (passed_word != 0u) {
        const size_t index = first + r * 32 + lane;
        bool is_settled = ((word >> lane) & 1u) != 0u;
        if (((passed_word >> lane) & 1u) != 0u) {
          const uint32_t fused =
              pack(fuse(unpack(voxels[r]), kValueScale, free_weight, max_weight));
          map[index] = fused;
          is_settled = fused == settled_voxel;
        }
        word = write_warp_bits(settled, index, is_settled);
        updated += static_cast<uint32_t>(__popc(passed_word));
      }
      all_settled = all_settled && word == 0xffffffffu;
    }
    if (lane == 0u) {
      brick_flags[brick] = 0u;
      settled_bricks[brick] = all_settled ? 1u : 0u;
    }
    brick = next_brick;
    settled_word = next_settled;
    free_word = next_free;
    next_brick = brick_after;
  }
  if (lane == 0u && updated != 0u) atomicAdd(voxels_updated, updated);
}

/// One warp per brick with a candidate: fuses the candidates, and +tau where a free-space bit
/// is set, into the map, resets them and the brick's flags for the next scan, and renews the
/// brick's settled bits and flag. Each lane first loads all its 16 keys, then the map voxels of
/// those that got one, so that a warp has up to 32 loads in flight: with one voxel a thread and
/// a barrier per brick, the fusion waited for memory brick by brick (a quarter of an outdoor
/// scan's time).
// At most 64 registers (four blocks a multiprocessor instead of three): more warps waiting
// for memory at once outweigh the few values it keeps in local memory (outdoor fusion 210 ->
// 200 µs on an H100).
__global__ void __launch_bounds__(kThreads, 4)
    fuse_bricks_kernel(const uint32_t* __restrict__ touched_bricks,
                       const uint32_t* __restrict__ touched_count,
                       uint32_t* __restrict__ brick_flags, uint32_t* __restrict__ band_bricks,
                       uint32_t* __restrict__ candidates, uint32_t* __restrict__ map,
                       uint32_t* __restrict__ settled, uint32_t* __restrict__ free_space,
                       uint8_t* __restrict__ settled_bricks, int32_t falloff, uint32_t max_weight,
                       uint32_t* __restrict__ voxels_updated) {
  const uint32_t count = *touched_count;
  const uint32_t settled_voxel = settled_free_voxel(max_weight);
  const uint32_t lane = threadIdx.x % 32u;
  const uint32_t warps = gridDim.x * blockDim.x / 32u;
  uint32_t updated_here = 0;  // lane 0's count of updated voxels over its bricks
  for (uint32_t k = (blockIdx.x * blockDim.x + threadIdx.x) / 32u; k < count; k += warps) {
    const uint32_t brick = touched_bricks[k];
    const size_t first = static_cast<size_t>(brick) * kBrickVoxels;
    // The brick's 16 words of settled and of free-space bits, word r in lane r; the
    // free-space bits are reset for the next scan.
    const bool word_lane = lane < static_cast<uint32_t>(kFuseRounds);
    const uint32_t settled_word = word_lane ? settled[first / 32 + lane] : 0u;
    const uint32_t free_word = word_lane ? free_space[first / 32 + lane] : 0u;
    if (free_word != 0u) free_space[first / 32 + lane] = 0u;
    uint32_t keys[kFuseRounds];
    uint32_t voxels[kFuseRounds];
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      keys[r] = candidates[first + r * 32 + lane];
    }
    uint32_t stored = 0;  // bit r: the candidate slot of round r holds a key to reset
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      if (keys[r] != kEmptyCandidate) stored |= 1u << r;
      const bool passed_free = ((__shfl_sync(0xffffffffu, free_word, r) >> lane) & 1u) != 0u;
      if (passed_free && kFreeSpaceKey < keys[r]) keys[r] = kFreeSpaceKey;
      voxels[r] = keys[r] != kEmptyCandidate ? map[first + r * 32 + lane] : 0u;
    }
    bool all_settled = true;
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      const size_t index = first + r * 32 + lane;
      const bool updated = keys[r] != kEmptyCandidate;
      bool is_settled = ((__shfl_sync(0xffffffffu, settled_word, r) >> lane) & 1u) != 0u;
      if (updated) {
        if (((stored >> r) & 1u) != 0u) candidates[index] = kEmptyCandidate;
        const int32_t value = candidate_value(keys[r]);
        const uint32_t fused =
            pack(fuse(unpack(voxels[r]), value, candidate_weight(value, falloff), max_weight));
        map[index] = fused;
        is_settled = fused == settled_voxel;
      }
      const uint32_t word = write_warp_bits(settled, index, is_settled);
      const uint32_t updated_lanes = __ballot_sync(0xffffffffu, updated);
      if (lane == 0u) updated_here += static_cast<uint32_t>(__popc(updated_lanes));
      all_settled = all_settled && word == 0xffffffffu;
    }
    if (lane == 0u) {
      brick_flags[brick] = 0u;
      band_bricks[brick] = 0u;
      settled_bricks[brick] = all_settled ? 1u : 0u;
    }
  }
  if (lane == 0u && updated_here != 0u) atomicAdd(voxels_updated, updated_here);
}

/// One block per brick, one thread per voxel: copies whole bricks between the map (at
/// their storage offsets) and a dense staging array (brick after brick).
__global__ void gather_bricks_kernel(const uint32_t* map, const uint64_t* offsets,
                                     uint32_t* staging) {
  staging[static_cast<size_t>(blockIdx.x) * kBrickVoxels + threadIdx.x] =
      map[offsets[blockIdx.x] + threadIdx.x];
}

__global__ void scatter_bricks_kernel(const uint32_t* staging, const uint64_t* offsets,
                                      uint32_t* map, uint32_t* settled, uint8_t* settled_bricks,
                                      uint32_t settled_voxel) {
  const size_t index = offsets[blockIdx.x] + threadIdx.x;
  const uint32_t voxel = staging[static_cast<size_t>(blockIdx.x) * kBrickVoxels + threadIdx.x];
  map[index] = voxel;
  write_warp_bits(settled, index, voxel == settled_voxel);
  const int all_settled = __syncthreads_and(voxel == settled_voxel);
  if (threadIdx.x == 0) settled_bricks[offsets[blockIdx.x] / kBrickVoxels] = all_settled != 0;
}

void* allocate_page_locked(size_t bytes) {
  void* block = nullptr;
  return cudaMallocHost(&block, bytes) == cudaSuccess ? block : nullptr;
}

void release_page_locked(void* block) { cudaFreeHost(block); }

class CudaIntegrator final : public Integrator {
 public:
  CudaIntegrator(const TsdfSettings& settings, Vec3 centre_m)
      : settings_(settings), geometry_(centred_geometry(settings, centre_m)) {
    const size_t n = geometry_.voxel_count();
    // The walks follow the storage index in 32 bits (ray_walk.hpp, WalkIndex).
    if (n > size_t{UINT32_MAX}) {
      throw std::invalid_argument("a local map of " + std::to_string(n) +
                                  " voxels: the CUDA backend holds at most 2^32 - 1 a volume "
                                  "(a larger voxel or a smaller map)");
    }
    FEATSENSE_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking));
    FEATSENSE_CUDA_CHECK(cudaStreamCreateWithFlags(&flag_stream_, cudaStreamNonBlocking));
    FEATSENSE_CUDA_CHECK(cudaEventCreateWithFlags(&flags_uploaded_, cudaEventDisableTiming));
    host_memory::enable_page_locking({&allocate_page_locked, &release_page_locked});
    int device = 0;
    int multiprocessors = 0;
    FEATSENSE_CUDA_CHECK(cudaGetDevice(&device));
    FEATSENSE_CUDA_CHECK(
        cudaDeviceGetAttribute(&multiprocessors, cudaDevAttrMultiProcessorCount, device));
    // Grid-stride kernels whose work count lives on the device get a grid that fills the GPU.
    resident_blocks_ = static_cast<unsigned int>(multiprocessors) * 8u;
    map_.reserve(n);
    candidates_.reserve(n);
    settled_.reserve(n / 32);
    free_space_.reserve(n / 32);
    const size_t bricks = n / kBrickVoxels;
    settled_bricks_.reserve(bricks);
    brick_flags_.reserve(bricks);
    band_bricks_.reserve(bricks);
    touched_bricks_.reserve(bricks);
    free_bricks_.reserve(bricks);
    counters_.reserve(kCounters);
    host_counters_.reserve(kCounters);
    FEATSENSE_CUDA_CHECK(
        cudaMemsetAsync(brick_flags_.data(), 0, bricks * sizeof(uint32_t), stream_));
    FEATSENSE_CUDA_CHECK(
        cudaMemsetAsync(band_bricks_.data(), 0, bricks * sizeof(uint32_t), stream_));
    FEATSENSE_CUDA_CHECK(cudaMemsetAsync(map_.data(), 0, n * sizeof(uint32_t), stream_));
    FEATSENSE_CUDA_CHECK(cudaMemsetAsync(settled_.data(), 0, n / 8, stream_));
    FEATSENSE_CUDA_CHECK(cudaMemsetAsync(free_space_.data(), 0, n / 8, stream_));
    FEATSENSE_CUDA_CHECK(cudaMemsetAsync(settled_bricks_.data(), 0, bricks, stream_));
    FEATSENSE_CUDA_CHECK(cudaMemsetAsync(candidates_.data(), 0xFF, n * sizeof(uint32_t), stream_));
    FEATSENSE_CUDA_CHECK(cudaStreamSynchronize(stream_));
  }
  ~CudaIntegrator() override {
    cudaEventDestroy(flags_uploaded_);
    cudaStreamDestroy(flag_stream_);
    cudaStreamDestroy(stream_);
  }

  std::string backend_name() const override { return "cuda"; }
  const LocalMapGeometry& geometry() const override { return geometry_; }
  size_t memory_bytes() const override {
    return map_.bytes() + candidates_.bytes() + settled_.bytes() + free_space_.bytes() +
           settled_bricks_.bytes() + brick_flags_.bytes() + band_bricks_.bytes() +
           touched_bricks_.bytes() + free_bricks_.bytes() + kept_.bytes() + endpoints_.bytes() +
           origins_.bytes() + counters_.bytes() + brick_offsets_.bytes() + brick_staging_.bytes() +
           interpolate_.bytes() + carving_level_.bytes();
  }

  std::vector<uint32_t> download() const override {
    std::vector<uint32_t> out(geometry_.voxel_count());
    FEATSENSE_CUDA_CHECK(cudaMemcpyAsync(out.data(), map_.data(), out.size() * sizeof(uint32_t),
                                         cudaMemcpyDeviceToHost, stream_));
    FEATSENSE_CUDA_CHECK(cudaStreamSynchronize(stream_));
    return out;
  }

  void read_bricks(const std::vector<Index3>& bricks,
                   std::vector<uint32_t>& voxels) const override {
    voxels.resize(bricks.size() * kBrickVoxels);
    for_each_brick_batch(bricks, [&](size_t first, size_t count) {
      gather_bricks_kernel<<<static_cast<unsigned int>(count), kBrickVoxels, 0, stream_>>>(
          map_.data(), brick_offsets_.data(), brick_staging_.data());
      FEATSENSE_CUDA_CHECK(cudaGetLastError());
      FEATSENSE_CUDA_CHECK(cudaMemcpyAsync(
          voxels.data() + first * kBrickVoxels, brick_staging_.data(),
          count * kBrickVoxels * sizeof(uint32_t), cudaMemcpyDeviceToHost, stream_));
      FEATSENSE_CUDA_CHECK(cudaStreamSynchronize(stream_));
    });
  }

  void write_bricks(const std::vector<Index3>& bricks,
                    const std::vector<uint32_t>& voxels) override {
    check_brick_voxels(bricks, voxels);
    for_each_brick_batch(bricks, [&](size_t first, size_t count) {
      FEATSENSE_CUDA_CHECK(cudaMemcpyAsync(
          brick_staging_.data(), voxels.data() + first * kBrickVoxels,
          count * kBrickVoxels * sizeof(uint32_t), cudaMemcpyHostToDevice, stream_));
      scatter_bricks_kernel<<<static_cast<unsigned int>(count), kBrickVoxels, 0, stream_>>>(
          brick_staging_.data(), brick_offsets_.data(), map_.data(), settled_.data(),
          settled_bricks_.data(), settled_free_voxel(settings_.max_weight_fixed()));
      FEATSENSE_CUDA_CHECK(cudaGetLastError());
      FEATSENSE_CUDA_CHECK(cudaStreamSynchronize(stream_));
    });
  }

  void set_origin(Index3 origin) override {
    check_brick_aligned(origin);
    geometry_.origin = origin;
  }

  IntegrationStats integrate(const RayBatch& rays) override {
    check_ray_batch(rays);
    const uint32_t n = static_cast<uint32_t>(rays.size());
    IntegrationStats stats;
    if (n == 0) return stats;
    const bool origin_per_point = rays.origins_m.size() > 1;
    const size_t origin_count = origin_per_point ? n : 1;
    upload(rays, origin_count);
    uint32_t* kept_count = counters_.data() + kKeptRays;
    uint32_t* touched_count = counters_.data() + kTouchedBricks;
    uint32_t* free_count = counters_.data() + kFreeBricks;
    uint32_t* updated_count = counters_.data() + kVoxelsUpdated;
    FEATSENSE_CUDA_CHECK(
        cudaMemsetAsync(counters_.data(), 0, kCounters * sizeof(uint32_t), stream_));

    kept_.grow(n);
    if (settings_.reduce_points_per_voxel) {
      mark_first_point_kernel<<<blocks_for(n), kThreads, 0, stream_>>>(
          endpoints_.data(), n, geometry_, candidates_.data());
      select_rays_kernel<<<blocks_for(n), kThreads, 0, stream_>>>(
          endpoints_.data(), n, geometry_, candidates_.data(), kept_.data(), kept_count);
    } else {
      fill_identity(n, kept_count);
    }
    FEATSENSE_CUDA_CHECK(cudaGetLastError());
    FEATSENSE_CUDA_CHECK(cudaStreamWaitEvent(stream_, flags_uploaded_, 0));

    detail::RayMarchParams params;
    params.truncation_m = settings_.truncation_m;
    params.interpolation_slope = settings_.interpolation_slope;
    params.up = rays.up;
    const ProposeCandidate propose{geometry_,           candidates_.data(), brick_flags_.data(),
                                   band_bricks_.data(), settled_.data(),    free_space_.data()};
    const uint8_t* interpolate = rays.interpolate.empty() ? nullptr : interpolate_.data();
    const uint8_t* carving_level = rays.carving_level.empty() ? nullptr : carving_level_.data();
    const auto walk_blocks = static_cast<unsigned int>((n + kWalkThreads - 1) / kWalkThreads);
    min_tsdf_kernel<<<walk_blocks* static_cast<unsigned int>(kWalkParts), kWalkThreads, 0,
                      stream_>>>(origins_.data(), origin_per_point, endpoints_.data(), interpolate,
                                 carving_level, settings_.carve_free_space, settings_.dense_range_m,
                                 kept_.data(), kept_count, params, propose, settled_bricks_.data());
    FEATSENSE_CUDA_CHECK(cudaGetLastError());
    const auto brick_count = static_cast<uint32_t>(geometry_.voxel_count() / kBrickVoxels);
    list_touched_bricks_kernel<<<blocks_for(brick_count), kThreads, 0, stream_>>>(
        brick_flags_.data(), band_bricks_.data(), brick_count, touched_bricks_.data(),
        touched_count, free_bricks_.data(), free_count);
    FEATSENSE_CUDA_CHECK(cudaGetLastError());
    fuse_bricks_kernel<<<resident_blocks_, kThreads, 0, stream_>>>(
        touched_bricks_.data(), touched_count, brick_flags_.data(), band_bricks_.data(),
        candidates_.data(), map_.data(), settled_.data(), free_space_.data(),
        settled_bricks_.data(), settings_.falloff_start_fixed(), settings_.max_weight_fixed(),
        updated_count);
    fuse_free_bricks_kernel<<<resident_blocks_, kThreads, 0, stream_>>>(
        free_bricks_.data(), free_count, brick_flags_.data(), map_.data(), settled_.data(),
        free_space_.data(), settled_bricks_.data(), settings_.falloff_start_fixed(),
        settings_.max_weight_fixed(), updated_count);
    FEATSENSE_CUDA_CHECK(cudaGetLastError());
    FEATSENSE_CUDA_CHECK(cudaMemcpyAsync(host_counters_.data(), counters_.data(),
                                         kCounters * sizeof(uint32_t), cudaMemcpyDeviceToHost,
                                         stream_));
    FEATSENSE_CUDA_CHECK(cudaStreamSynchronize(stream_));
    stats.rays = host_counters_.data()[kKeptRays];
    stats.voxels_updated = host_counters_.data()[kVoxelsUpdated];
    return stats;
  }

 private:
  enum Counter { kKeptRays, kTouchedBricks, kFreeBricks, kVoxelsUpdated, kCounters };

  /// The points go first; the per-point flags, which only the walk reads, on a stream of their
  /// own, so that their copy overlaps the selection of the rays (the walk waits for them).
  void upload(const RayBatch& rays, size_t origin_count) {
    const size_t n = rays.size();
    endpoints_.grow(n);
    origins_.grow(origin_count);
    upload_array(endpoints_.data(), rays.endpoints_m.data(), n, endpoint_staging_, stream_);
    upload_array(origins_.data(), rays.origins_m.data(), origin_count, origin_staging_, stream_);
    if (!rays.interpolate.empty()) {
      interpolate_.grow(n);
      upload_array(interpolate_.data(), rays.interpolate.data(), n, interpolate_staging_,
                   flag_stream_);
    }
    if (!rays.carving_level.empty()) {
      carving_level_.grow(n);
      upload_array(carving_level_.data(), rays.carving_level.data(), n, carving_level_staging_,
                   flag_stream_);
    }
    FEATSENSE_CUDA_CHECK(cudaEventRecord(flags_uploaded_, flag_stream_));
  }

  /// One DMA from page-locked memory (host_memory.hpp, where a RayBatch's arrays are once this
  /// integrator exists); other memory is copied into a page-locked staging buffer first.
  template <typename T>
  void upload_array(T* device, const T* host, size_t count, cuda::PinnedBuffer<T>& staging,
                    cudaStream_t stream) {
    const T* source = host;
    if (!host_memory::is_page_locked(host)) {
      staging.grow(count);
      detail::parallel_copy(staging.data(), host, count * sizeof(T));
      source = staging.data();
    }
    FEATSENSE_CUDA_CHECK(
        cudaMemcpyAsync(device, source, count * sizeof(T), cudaMemcpyHostToDevice, stream));
  }

  void fill_identity(uint32_t n, uint32_t* kept_count);

  /// Runs copy(first, count) over batches of `bricks` with the batch's storage offsets in
  /// brick_offsets_: batches bound the staging memory that moving the map takes on the device.
  template <typename Copy>
  void for_each_brick_batch(const std::vector<Index3>& bricks, const Copy& copy) const {
    constexpr size_t kBatchBricks = 16384;  // 32 MB of voxels
    for (const Index3& brick : bricks) check_brick_inside(geometry_, brick);
    for (size_t first = 0; first < bricks.size(); first += kBatchBricks) {
      const size_t count = std::min(kBatchBricks, bricks.size() - first);
      host_offsets_.resize(count);
      for (size_t k = 0; k < count; ++k) {
        host_offsets_[k] = geometry_.brick_offset(bricks[first + k]);
      }
      brick_offsets_.reserve(count);
      brick_staging_.reserve(count * kBrickVoxels);
      FEATSENSE_CUDA_CHECK(cudaMemcpyAsync(brick_offsets_.data(), host_offsets_.data(),
                                           count * sizeof(uint64_t), cudaMemcpyHostToDevice,
                                           stream_));
      copy(first, count);
    }
  }

  TsdfSettings settings_;
  LocalMapGeometry geometry_;
  cudaStream_t stream_ = nullptr;
  cudaStream_t flag_stream_ = nullptr;    ///< uploads the per-point flags (upload)
  cudaEvent_t flags_uploaded_ = nullptr;  ///< recorded on flag_stream_ after them
  cuda::DeviceBuffer<uint32_t> map_;
  cuda::DeviceBuffer<uint32_t> candidates_;
  cuda::DeviceBuffer<uint32_t> settled_;         ///< a bit per voxel of settled free space
  cuda::DeviceBuffer<uint32_t> free_space_;      ///< a bit per voxel passed in free space
  cuda::DeviceBuffer<uint8_t> settled_bricks_;   ///< 1 per brick of settled free space only
  cuda::DeviceBuffer<uint32_t> brick_flags_;     ///< 1 while a brick is in touched_bricks_
  cuda::DeviceBuffer<uint32_t> band_bricks_;     ///< 1 per brick of those with a candidate
  cuda::DeviceBuffer<uint32_t> touched_bricks_;  ///< bricks with a candidate this scan
  cuda::DeviceBuffer<uint32_t> free_bricks_;     ///< bricks only passed in free space
  unsigned int resident_blocks_ = 1;
  cuda::DeviceBuffer<uint32_t> kept_;
  cuda::DeviceBuffer<uint32_t> counters_;
  cuda::PinnedBuffer<uint32_t> host_counters_;
  cuda::DeviceBuffer<Vec3> endpoints_;
  cuda::DeviceBuffer<Vec3> origins_;
  cuda::PinnedBuffer<Vec3> endpoint_staging_;  ///< for end points not in page-locked memory
  cuda::PinnedBuffer<Vec3> origin_staging_;
  cuda::DeviceBuffer<uint8_t> interpolate_;  ///< per end point, when the batch has flags
  cuda::PinnedBuffer<uint8_t> interpolate_staging_;
  cuda::DeviceBuffer<uint8_t> carving_level_;  ///< per end point, when the batch has levels
  cuda::PinnedBuffer<uint8_t> carving_level_staging_;
  // Moving the map: the storage offsets of a batch of bricks and their voxels.
  mutable std::vector<uint64_t> host_offsets_;
  mutable cuda::DeviceBuffer<uint64_t> brick_offsets_;
  mutable cuda::DeviceBuffer<uint32_t> brick_staging_;
};

__global__ void identity_kernel(uint32_t* kept, uint32_t n, uint32_t* kept_count) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i == 0) *kept_count = n;
  if (i < n) kept[i] = i;
}

void CudaIntegrator::fill_identity(uint32_t n, uint32_t* kept_count) {
  identity_kernel<<<blocks_for(n), kThreads, 0, stream_>>>(kept_.data(), n, kept_count);
}

}  // namespace

bool cuda_backend_available(std::string* why) {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess || count == 0) {
    if (why) {
      *why = status != cudaSuccess ? std::string("no usable GPU: ") + cudaGetErrorString(status)
                                   : std::string("no GPU found");
    }
    return false;
  }
  cudaDeviceProp properties{};
  if (cudaGetDeviceProperties(&properties, 0) == cudaSuccess && why) {
    *why = std::string("GPU ") + properties.name;
  }
  return true;
}

std::unique_ptr<Integrator> make_cuda_integrator(const TsdfSettings& settings, Vec3 centre_m) {
  std::string why;
  if (!cuda_backend_available(&why))
    throw std::runtime_error("the CUDA backend is unavailable: " + why);
  return std::make_unique<CudaIntegrator>(settings, centre_m);
}

}  // namespace featsense::tsdf
