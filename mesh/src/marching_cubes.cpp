#include "featsense/mesh/marching_cubes.hpp"

#include <chrono>
#include <stdexcept>
#include <string>

#include "internal/chunk_set_mesher.hpp"
#include "internal/dense_block_store.hpp"

namespace featsense::mesh {

TriangleMesh extract_mesh(storage::ChunkStore& store, const MeshingSettings& settings,
                          MeshingStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const storage::MapMetadata& metadata = store.metadata();
  internal::check_meshing_settings(settings, metadata);
  const std::vector<storage::ChunkKey> stored = store.keys();
  const std::vector<internal::ChunkWork> work = internal::chunk_work(stored, settings, metadata);
  return internal::mesh_chunk_work(store, stored, work, settings.threads, start, stats);
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
  internal::check_meshing_settings(settings, metadata);
  internal::ChunkMeshingParameters parameters;
  parameters.voxel_size_m = voxel_size_m;
  parameters.min_weight_fixed = internal::min_weight_fixed(min_weight);
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
