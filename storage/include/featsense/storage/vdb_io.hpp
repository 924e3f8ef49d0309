#pragma once
/// OpenVDB export and import of a map, so that other tools can open it: two float grids in
/// one .vdb file, "tsdf" (signed distance, metres, within +/- tau) and "weight"
/// (measurements). Index space is the global voxel grid: VDB voxel (i, j, k) is global voxel
/// (i, j, k), its centre at ((i, j, k) + 0.5) * voxel_size_m in the map frame. Only observed
/// voxels (weight > 0) are active. The tsdf grid carries the metadata "truncation_m".

#include <filesystem>

#include "featsense/storage/chunk_store.hpp"

namespace featsense::storage {

struct VdbExportStats {
  std::size_t chunks = 0;
  std::size_t active_voxels = 0;
};

/// Writes every chunk of `store` to `vdb_path`. Throws std::runtime_error (with the path).
VdbExportStats export_vdb(ChunkStore& store, const std::filesystem::path& vdb_path);

/// The voxel size and tau of a .vdb made by export_vdb (the rest of MapMetadata at its
/// defaults), read without its voxels: what a store needs before import_vdb. Throws
/// std::runtime_error naming the file when it cannot be read or lacks the grids or tau.
MapMetadata read_vdb_metadata(const std::filesystem::path& vdb_path);

/// Writes the voxels of a .vdb made by export_vdb into `store`, converting back to the fixed
/// point of voxel.hpp, which export_vdb's floats hold exactly enough to round back to the
/// same integers. The file's voxel size and tau must match the store's, else
/// std::runtime_error naming both. Chunks are assembled in memory before they are written.
VdbExportStats import_vdb(const std::filesystem::path& vdb_path, ChunkStore& store);

}  // namespace featsense::storage
