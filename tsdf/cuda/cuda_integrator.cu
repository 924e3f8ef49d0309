// The CUDA integrator: the same rule as the reference integrator and the CPU integrator
// (voxel.hpp, ray_walk.hpp), bit for bit, in six kernels per scan: keep one end point per voxel
// (two, select_rays.cuh), the per-scan minimum (walk_kernel.cuh: atomicMin on the ordered
// candidate keys; free space, whose key is always +tau, as a bit per voxel), the lists of
// touched bricks (with candidates, and only passed in free space), and the fusion of each
// list's voxels with the reset of the candidates and bits (fuse_kernels.cuh). Free-space
// candidates pass settled free space by (voxel.hpp, settled_free_voxel), found in a bit per
// voxel that the fusion keeps. This file holds the host side: buffers, uploads, launches.

#include <cuda_runtime.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "brick_checks.hpp"
#include "brick_kernels.cuh"
#include "cuda_check.hpp"
#include "device_buffer.hpp"
#include "featsense/tsdf/host_memory.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "fuse_kernels.cuh"
#include "kernel_common.cuh"
#include "parallel_copy.hpp"
#include "select_rays.cuh"
#include "walk_kernel.cuh"

namespace featsense::tsdf {
namespace {

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
      cuda::gather_bricks_kernel<<<static_cast<unsigned int>(count), kBrickVoxels, 0, stream_>>>(
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
      cuda::scatter_bricks_kernel<<<static_cast<unsigned int>(count), kBrickVoxels, 0, stream_>>>(
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
      cuda::mark_first_point_kernel<<<cuda::blocks_for(n), cuda::kThreads, 0, stream_>>>(
          endpoints_.data(), n, geometry_, candidates_.data());
      cuda::select_rays_kernel<<<cuda::blocks_for(n), cuda::kThreads, 0, stream_>>>(
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
    const cuda::ProposeCandidate propose{geometry_,           candidates_.data(),
                                         brick_flags_.data(), band_bricks_.data(),
                                         settled_.data(),     free_space_.data()};
    const uint8_t* interpolate = rays.interpolate.empty() ? nullptr : interpolate_.data();
    const uint8_t* carving_level = rays.carving_level.empty() ? nullptr : carving_level_.data();
    const auto walk_blocks =
        static_cast<unsigned int>((n + cuda::kWalkThreads - 1) / cuda::kWalkThreads);
    cuda::min_tsdf_kernel<<<walk_blocks* static_cast<unsigned int>(cuda::kWalkParts),
                            cuda::kWalkThreads, 0, stream_>>>(
        origins_.data(), origin_per_point, endpoints_.data(), interpolate, carving_level,
        settings_.carve_free_space, settings_.dense_range_m, kept_.data(), kept_count, params,
        propose, settled_bricks_.data());
    FEATSENSE_CUDA_CHECK(cudaGetLastError());
    const auto brick_count = static_cast<uint32_t>(geometry_.voxel_count() / kBrickVoxels);
    cuda::list_touched_bricks_kernel<<<cuda::blocks_for(brick_count), cuda::kThreads, 0, stream_>>>(
        brick_flags_.data(), band_bricks_.data(), brick_count, touched_bricks_.data(),
        touched_count, free_bricks_.data(), free_count);
    FEATSENSE_CUDA_CHECK(cudaGetLastError());
    cuda::fuse_bricks_kernel<<<resident_blocks_, cuda::kThreads, 0, stream_>>>(
        touched_bricks_.data(), touched_count, brick_flags_.data(), band_bricks_.data(),
        candidates_.data(), map_.data(), settled_.data(), free_space_.data(),
        settled_bricks_.data(), settings_.falloff_start_fixed(), settings_.max_weight_fixed(),
        updated_count);
    cuda::fuse_free_bricks_kernel<<<resident_blocks_, cuda::kThreads, 0, stream_>>>(
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

void CudaIntegrator::fill_identity(uint32_t n, uint32_t* kept_count) {
  cuda::identity_kernel<<<cuda::blocks_for(n), cuda::kThreads, 0, stream_>>>(kept_.data(), n,
                                                                             kept_count);
}

}  // namespace

std::unique_ptr<Integrator> make_cuda_integrator(const TsdfSettings& settings, Vec3 centre_m) {
  std::string why;
  if (!cuda_backend_available(&why))
    throw std::runtime_error("the CUDA backend is unavailable: " + why);
  return std::make_unique<CudaIntegrator>(settings, centre_m);
}

}  // namespace featsense::tsdf
