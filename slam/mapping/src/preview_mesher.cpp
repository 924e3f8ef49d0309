#include "preview_mesher.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "background_thread.hpp"
#include "featsense/mesh/marching_cubes.hpp"

namespace featsense::mapping {
namespace {

using Clock = std::chrono::steady_clock;

int32_t chunk_index(double metres, double chunk_m) {
  return static_cast<int32_t>(std::floor(metres / chunk_m));
}

/// Squared distance from the chunk's centre to `p`, metres.
double distance2(const storage::ChunkKey& key, double chunk_m, const Eigen::Vector3d& p) {
  const Eigen::Vector3d centre = (Eigen::Vector3d(key.x, key.y, key.z).array() + 0.5) * chunk_m;
  return (centre - p).squaredNorm();
}

}  // namespace

PreviewMesher::PreviewMesher(MapPreviewSettings settings, double voxel_size_m, double truncation_m)
    : settings_(std::move(settings)),
      voxel_size_m_(voxel_size_m),
      truncation_m_(truncation_m),
      last_refresh_(Clock::now()) {
  settings_.max_chunks = std::max<size_t>(1, settings_.max_chunks);
  thread_ = std::thread([this] { mesh_jobs(); });
}

PreviewMesher::~PreviewMesher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void PreviewMesher::mark(const tsdf::RayBatch& rays, const tsdf::LocalMapGeometry& bounds) {
  const double chunk_m = voxel_size_m_ * storage::kChunkSize;
  // A point changes voxels up to tau around it; the cubes of the chunk below meet a chunk's
  // first voxel, so a point within a voxel of a chunk's lower face changes that one too.
  const double below = truncation_m_ + voxel_size_m_;
  const double above = truncation_m_;
  const auto margin = static_cast<float>(truncation_m_);
  const tsdf::Vec3 lo_m = bounds.min_corner();
  const tsdf::Vec3 hi_m = bounds.max_corner();
  storage::ChunkKey last{INT32_MIN, INT32_MIN, INT32_MIN};
  for (const tsdf::Vec3& p : rays.endpoints_m) {
    // NaN fails these too.
    if (!(p.x >= lo_m.x - margin && p.x < hi_m.x + margin && p.y >= lo_m.y - margin &&
          p.y < hi_m.y + margin && p.z >= lo_m.z - margin && p.z < hi_m.z + margin)) {
      continue;
    }
    const storage::ChunkKey lo{chunk_index(p.x - below, chunk_m), chunk_index(p.y - below, chunk_m),
                               chunk_index(p.z - below, chunk_m)};
    const storage::ChunkKey hi{chunk_index(p.x + above, chunk_m), chunk_index(p.y + above, chunk_m),
                               chunk_index(p.z + above, chunk_m)};
    if (lo == hi) {
      // Neighbouring points of an organized scan mostly fall into the same chunk.
      if (lo != last) changed_.insert(lo);
      last = lo;
      continue;
    }
    for (int32_t z = lo.z; z <= hi.z; ++z)
      for (int32_t y = lo.y; y <= hi.y; ++y)
        for (int32_t x = lo.x; x <= hi.x; ++x) changed_.insert({x, y, z});
  }
}

void PreviewMesher::add_pose(int64_t stamp_ns, const Eigen::Isometry3d& pose) {
  new_poses_.push_back(stamp_ns, pose);
}

bool PreviewMesher::due() const {
  if (std::chrono::duration<double>(Clock::now() - last_refresh_).count() < settings_.interval_s)
    return false;
  std::lock_guard<std::mutex> lock(mutex_);
  return !job_;
}

void PreviewMesher::refresh(storage::ShiftingMap* map, const Eigen::Vector3d& sensor,
                            MapPreview status) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (job_) return;  // the previous refresh is still being meshed: not due
  }
  last_refresh_ = Clock::now();
  Job job;
  if (map != nullptr && !changed_.empty()) {
    const double chunk_m = voxel_size_m_ * storage::kChunkSize;
    std::vector<storage::ChunkKey> keys(changed_.begin(), changed_.end());
    const size_t count = std::min(settings_.max_chunks, keys.size());
    std::partial_sort(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(count), keys.end(),
                      [&](const storage::ChunkKey& a, const storage::ChunkKey& b) {
                        return distance2(a, chunk_m, sensor) < distance2(b, chunk_m, sensor);
                      });
    keys.resize(count);
    constexpr int32_t n = mesh::kPaddedChunkSize;
    std::vector<tsdf::Index3> origins;
    for (const storage::ChunkKey& key : keys) {
      origins.push_back({key.x * storage::kChunkSize - 1, key.y * storage::kChunkSize - 1,
                         key.z * storage::kChunkSize - 1});
      changed_.erase(key);
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job.blocks = std::move(spare_blocks_);
    }
    map->read_blocks(origins, {n, n, n}, job.blocks);
    job.keys = std::move(keys);
  }
  status.refresh = ++refreshes_;
  status.chunks_waiting = changed_.size();
  status.new_poses = std::move(new_poses_);
  new_poses_ = {};
  job.preview = std::move(status);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = std::move(job);
  }
  wake_.notify_all();
}

void PreviewMesher::finish(storage::ShiftingMap* map, const Eigen::Vector3d& sensor,
                           MapPreview status) {
  do {
    wait_idle();
    MapPreview next = status;
    next.last = changed_.size() <= settings_.max_chunks || map == nullptr;
    refresh(map, sensor, std::move(next));
  } while (!changed_.empty() && map != nullptr);
  wait_idle();
}

void PreviewMesher::wait_idle() {
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.wait(lock, [this] { return !job_ || stopping_; });
}

void PreviewMesher::mesh_jobs() {
  // The lowest priority of the pass: a preview never holds the map up.
  BackgroundThread background(kBackgroundNice);
  while (true) {
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait(lock, [this] { return job_.has_value() || stopping_; });
    if (stopping_) return;
    Job& job = *job_;
    lock.unlock();

    try {
      const Clock::time_point start = Clock::now();
      job.preview.chunks.resize(job.keys.size());
      background.run([&] {
        tbb::parallel_for(size_t{0}, job.keys.size(), [&](size_t i) {
          job.preview.chunks[i].key = job.keys[i];
          job.preview.chunks[i].mesh = mesh::extract_chunk_mesh(
              job.keys[i], job.blocks[i], voxel_size_m_, settings_.min_weight);
        });
      });
      job.preview.meshing_ms =
          std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      if (settings_.deliver) settings_.deliver(std::move(job.preview));
    } catch (...) {
      // The preview is for watching: a refresh that failed (a viewer's error, memory) must not
      // stop the mapping; the next one comes as usual.
    }

    lock.lock();
    spare_blocks_ = std::move(job.blocks);
    job_.reset();
    lock.unlock();
    wake_.notify_all();
  }
}

}  // namespace featsense::mapping
