#include "featsense/mesh/marching_cubes.hpp"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "featsense/tsdf/voxel.hpp"
#include "internal/chunk_mesher.hpp"
#include "internal/dense_block_store.hpp"
#include "internal/mesh_welder.hpp"
#include "internal/padded_chunk_reader.hpp"

namespace featsense::mesh {
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
                      internal::ChunkMeshingParameters& parameters) {
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

void check_settings(const MeshingSettings& settings, const storage::MapMetadata& metadata) {
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

/// At least 1: an unobserved voxel (weight 0) never takes part, whatever the setting.
uint32_t min_weight_fixed(double min_weight) {
  return std::max<uint32_t>(
      1u, static_cast<uint32_t>(std::min(65535.0, std::round(min_weight * tsdf::kWeightScale))));
}

struct WorkItem {
  internal::ChunkNeighbourhood neighbourhood;
  internal::ChunkMeshingParameters parameters;
};

/// Assembles the padded chunk (in a buffer kept per thread) and meshes it, unless a cheap
/// look at the signs shows that nothing is to be found.
internal::ChunkMesh mesh_item(const WorkItem& item) {
  if (!internal::may_have_faces(item.neighbourhood, item.parameters.min_weight_fixed)) return {};
  thread_local internal::PaddedBlock block;
  internal::fill_padded_block(item.neighbourhood, block);
  return internal::mesh_chunk(block, item.parameters);
}

}  // namespace

TriangleMesh extract_mesh(storage::ChunkStore& store, const MeshingSettings& settings,
                          MeshingStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const storage::MapMetadata& metadata = store.metadata();
  check_settings(settings, metadata);

  internal::ChunkMeshingParameters base;
  base.voxel_size_m = metadata.voxel_size_m;
  base.min_weight_fixed = min_weight_fixed(settings.min_weight);
  const CubeBounds bounds = cube_bounds(settings, metadata.voxel_size_m);

  const std::vector<ChunkKey> stored = store.keys();
  std::vector<std::pair<ChunkKey, internal::ChunkMeshingParameters>> work;
  for (const ChunkKey& key : stored) {
    internal::ChunkMeshingParameters parameters = base;
    if (local_cube_range(key, bounds, parameters)) work.emplace_back(key, parameters);
  }

  internal::PaddedChunkReader reader(store, stored);
  internal::MeshWelder welder(true);
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    // Chunks are read in order by one thread (the store is not thread-safe), padded and
    // meshed in parallel and welded in the same order, so the mesh does not depend on the
    // threads; the tokens bound the chunks in flight.
    const auto tokens = static_cast<size_t>(2 * arena.max_concurrency() + 2);
    size_t next = 0;
    tbb::parallel_pipeline(
        tokens,
        tbb::make_filter<void, std::shared_ptr<WorkItem>>(
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
            tbb::make_filter<std::shared_ptr<WorkItem>, std::shared_ptr<internal::ChunkMesh>>(
                tbb::filter_mode::parallel,
                [](const std::shared_ptr<WorkItem>& item) {
                  return std::make_shared<internal::ChunkMesh>(mesh_item(*item));
                }) &
            tbb::make_filter<std::shared_ptr<internal::ChunkMesh>, void>(
                tbb::filter_mode::serial_in_order,
                [&](const std::shared_ptr<internal::ChunkMesh>& part) { welder.add(*part); }));
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

TriangleMesh extract_mesh(const std::vector<uint32_t>& voxels, tsdf::Index3 origin,
                          tsdf::Index3 dim, double voxel_size_m, double truncation_m,
                          const MeshingSettings& settings, MeshingStats* stats) {
  storage::MapMetadata metadata;
  metadata.voxel_size_m = voxel_size_m;
  metadata.truncation_m = truncation_m;
  internal::DenseBlockStore store(voxels, origin, dim, metadata);
  return extract_mesh(store, settings, stats);
}

static_assert(kPaddedChunkSize == internal::kPaddedSize);

TriangleMesh extract_chunk_mesh(const storage::ChunkKey& key, std::vector<uint32_t>& padded,
                                double voxel_size_m, double min_weight) {
  if (padded.size() != internal::kPaddedVoxels) {
    throw std::invalid_argument("a chunk's padded block holds " +
                                std::to_string(internal::kPaddedVoxels) + " voxels, got " +
                                std::to_string(padded.size()));
  }
  MeshingSettings settings;
  settings.min_weight = min_weight;
  storage::MapMetadata metadata;
  metadata.voxel_size_m = voxel_size_m;
  metadata.truncation_m = 1.0;  // not used by the cubes; checked only to be positive
  check_settings(settings, metadata);
  internal::ChunkMeshingParameters parameters;
  parameters.voxel_size_m = voxel_size_m;
  parameters.min_weight_fixed = min_weight_fixed(min_weight);
  internal::PaddedBlock block;
  block.key = key;
  block.voxels.swap(padded);
  internal::ChunkMesh part = internal::mesh_chunk(block, parameters);
  block.voxels.swap(padded);
  TriangleMesh mesh;
  mesh.vertices = std::move(part.vertices);
  mesh.normals = std::move(part.normals);
  mesh.triangles = std::move(part.triangles);
  return mesh;
}

}  // namespace featsense::mesh
