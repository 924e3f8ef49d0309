#pragma once
/// Marching cubes over a set of stored chunks: the work list (which chunks, which of their
/// cubes) and the pipeline that reads, meshes and welds them. Shared by the whole-map meshing
/// and the tiles.

#include <chrono>
#include <cstdint>
#include <utility>
#include <vector>

#include "featsense/mesh/marching_cubes.hpp"
#include "internal/chunk_mesher.hpp"

namespace featsense::mesh::internal {

/// A chunk to mesh and the range of its cubes to mesh.
using ChunkWork = std::pair<storage::ChunkKey, ChunkMeshingParameters>;

/// Throws std::invalid_argument for bad settings or metadata (voxel size or tau not positive).
void check_meshing_settings(const MeshingSettings& settings, const storage::MapMetadata& metadata);

/// At least 1: an unobserved voxel (weight 0) never takes part, whatever the setting.
uint32_t min_weight_fixed(double min_weight);

/// The chunks of `keys` (sorted) with cubes inside the settings' bbox, and those cubes.
std::vector<ChunkWork> chunk_work(const std::vector<storage::ChunkKey>& keys,
                                  const MeshingSettings& settings,
                                  const storage::MapMetadata& metadata);

/// Meshes `work` (in its order) into one welded mesh. `readable` are the stored keys (sorted)
/// that the work's chunks and their neighbours are read from: the chunks of `work` and any
/// stored neighbours they have; a neighbour left out counts as unobserved. Reads the store from
/// one thread; the result does not depend on `threads` (0 = all cores). Fills `stats` where
/// given, its time counted from `start`.
TriangleMesh mesh_chunk_work(storage::ChunkStore& store,
                             const std::vector<storage::ChunkKey>& readable,
                             const std::vector<ChunkWork>& work, int threads,
                             std::chrono::steady_clock::time_point start, MeshingStats* stats);

}  // namespace featsense::mesh::internal
