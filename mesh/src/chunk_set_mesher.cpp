#include "internal/chunk_set_mesher.hpp"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "featsense/tsdf/voxel.hpp"
#include "internal/mesh_welder.hpp"
#include "internal/padded_chunk_reader.hpp"

namespace featsense::mesh::internal {
namespace {

using storage::ChunkKey;
using storage::kChunkSize;

/// Global cube indices (lower corner voxels) that meshing may use, inclusive per axis.
struct CubeBounds {
  Eigen::Array3d lo = Eigen::Array3d::Constant(-1e18);
  Eigen::Array3d hi = Eigen::Array3d::Constant(1e18);
};

CubeBounds cube_bounds(const MeshingSettings& settings, double voxel_size_m) {
  CubeBounds bounds;
  if (!settings.bbox) return bounds;
  // Cube g spans the voxel centres (g + 0.5) .. (g + 1.5) voxels; all of it must be inside.
  bounds.lo = (settings.bbox->min().array() / voxel_size_m - 0.5).ceil();
  bounds.hi = (settings.bbox->max().array() / voxel_size_m - 1.5).floor();
  return bounds;
}

/// The chunk-local cube range inside the bounds; false when it is empty.
bool local_cube_range(const ChunkKey& key, const CubeBounds& bounds,
                      ChunkMeshingParameters& parameters) {
  const Eigen::Array3d first = Eigen::Array3d(key.x, key.y, key.z) * kChunkSize;
  const Eigen::Array3d begin = (bounds.lo - first).max(0.0).min(kChunkSize);
  const Eigen::Array3d end = (bounds.hi + 1.0 - first).max(0.0).min(kChunkSize);
  if ((begin >= end).any()) return false;
  parameters.cube_begin = {static_cast<int32_t>(begin.x()), static_cast<int32_t>(begin.y()),
                           static_cast<int32_t>(begin.z())};
  parameters.cube_end = {static_cast<int32_t>(end.x()), static_cast<int32_t>(end.y()),
                         static_cast<int32_t>(end.z())};
  return true;
}

struct WorkItem {
  ChunkNeighbourhood neighbourhood;
  ChunkMeshingParameters parameters;
};

/// Assembles the padded chunk (in a buffer kept per thread) and meshes it, unless a cheap
/// look at the signs shows that nothing is to be found.
ChunkMesh mesh_item(const WorkItem& item) {
  if (!may_have_faces(item.neighbourhood, item.parameters.min_weight_fixed)) return {};
  thread_local PaddedBlock block;
  fill_padded_block(item.neighbourhood, block);
  return mesh_chunk(block, item.parameters);
}

}  // namespace

void check_meshing_settings(const MeshingSettings& settings, const storage::MapMetadata& metadata) {
  if (!std::isfinite(settings.min_weight) || settings.min_weight < 0.0) {
    throw std::invalid_argument("min_weight must be a number >= 0, got " +
                                std::to_string(settings.min_weight));
  }
  if (settings.threads < 0) {
    throw std::invalid_argument("threads must be >= 0 (0 = all cores), got " +
                                std::to_string(settings.threads));
  }
  if (settings.bbox && (!settings.bbox->min().allFinite() || !settings.bbox->max().allFinite() ||
                        (settings.bbox->min().array() > settings.bbox->max().array()).any())) {
    throw std::invalid_argument("bbox: the minimum must not exceed the maximum on any axis");
  }
  if (!(metadata.voxel_size_m > 0.0) || !(metadata.truncation_m > 0.0)) {
    throw std::invalid_argument("map metadata: voxel size and truncation must be positive");
  }
}

uint32_t min_weight_fixed(double min_weight) {
  return std::max<uint32_t>(
      1u, static_cast<uint32_t>(std::min(65535.0, std::round(min_weight * tsdf::kWeightScale))));
}

std::vector<ChunkWork> chunk_work(const std::vector<ChunkKey>& keys,
                                  const MeshingSettings& settings,
                                  const storage::MapMetadata& metadata) {
  ChunkMeshingParameters base;
  base.voxel_size_m = metadata.voxel_size_m;
  base.min_weight_fixed = min_weight_fixed(settings.min_weight);
  const CubeBounds bounds = cube_bounds(settings, metadata.voxel_size_m);
  std::vector<ChunkWork> work;
  for (const ChunkKey& key : keys) {
    ChunkMeshingParameters parameters = base;
    if (local_cube_range(key, bounds, parameters)) work.emplace_back(key, parameters);
  }
  return work;
}

TriangleMesh mesh_chunk_work(storage::ChunkStore& store, const std::vector<ChunkKey>& readable,
                             const std::vector<ChunkWork>& work, int threads,
                             std::chrono::steady_clock::time_point start, MeshingStats* stats) {
  PaddedChunkReader reader(store, readable);
  MeshWelder welder(true);
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    // Chunks are read in order by one thread (the store is not thread-safe), padded and
    // meshed in parallel and welded in the same order, so the mesh does not depend on the
    // threads; the tokens bound the chunks in flight.
    const auto tokens = static_cast<size_t>(2 * arena.max_concurrency() + 2);
    size_t next = 0;
    tbb::parallel_pipeline(
        tokens, tbb::make_filter<void, std::shared_ptr<WorkItem>>(
                    tbb::filter_mode::serial_in_order,
                    [&](tbb::flow_control& control) -> std::shared_ptr<WorkItem> {
                      if (next == work.size()) {
                        control.stop();
                        return nullptr;
                      }
                      auto item = std::make_shared<WorkItem>();
                      item->neighbourhood = reader.read(work[next].first);
                      item->parameters = work[next].second;
                      ++next;
                      return item;
                    }) &
                    tbb::make_filter<std::shared_ptr<WorkItem>, std::shared_ptr<ChunkMesh>>(
                        tbb::filter_mode::parallel,
                        [](const std::shared_ptr<WorkItem>& item) {
                          return std::make_shared<ChunkMesh>(mesh_item(*item));
                        }) &
                    tbb::make_filter<std::shared_ptr<ChunkMesh>, void>(
                        tbb::filter_mode::serial_in_order,
                        [&](const std::shared_ptr<ChunkMesh>& part) { welder.add(*part); }));
  });
  TriangleMesh mesh = welder.take();
  if (stats != nullptr) {
    stats->chunks = work.size();
    stats->voxels = work.size() * storage::kChunkVoxels;
    stats->triangles = mesh.triangles.size();
    stats->vertices = mesh.vertices.size();
    stats->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return mesh;
}

}  // namespace featsense::mesh::internal
