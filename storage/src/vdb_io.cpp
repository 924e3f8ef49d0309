#include "featsense/storage/vdb_io.hpp"

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "featsense/tsdf/voxel.hpp"

namespace featsense::storage {

namespace {

constexpr const char* kTruncationKey = "truncation_m";

openvdb::math::Transform::Ptr voxel_transform(double voxel_size_m) {
  auto transform = openvdb::math::Transform::createLinearTransform(voxel_size_m);
  // VDB places voxel centres at index * size; ours are at (index + 0.5) * size.
  transform->postTranslate(openvdb::Vec3d(0.5 * voxel_size_m));
  return transform;
}

std::string describe(double metres) {
  std::ostringstream out;
  out.precision(10);  // enough to tell settings apart, short enough to read
  out << metres << " m";
  return out.str();
}

bool same_length(double a, double b) {
  return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
}

}  // namespace

VdbExportStats export_vdb(ChunkStore& store, const std::filesystem::path& vdb_path) {
  openvdb::initialize();
  const MapMetadata& metadata = store.metadata();
  const double tau = metadata.truncation_m;
  auto tsdf = openvdb::FloatGrid::create(0.0f);
  auto weight = openvdb::FloatGrid::create(0.0f);
  tsdf->setName("tsdf");
  weight->setName("weight");
  tsdf->setGridClass(openvdb::GRID_LEVEL_SET);
  tsdf->setTransform(voxel_transform(metadata.voxel_size_m));
  weight->setTransform(voxel_transform(metadata.voxel_size_m));
  tsdf->insertMeta(kTruncationKey, openvdb::DoubleMetadata(tau));

  VdbExportStats stats;
  auto tsdf_access = tsdf->getAccessor();
  auto weight_access = weight->getAccessor();
  for (const ChunkKey& key : store.keys()) {
    const auto chunk = store.read(key);
    if (!chunk) continue;
    ++stats.chunks;
    for (int32_t z = 0; z < kChunkSize; ++z)
      for (int32_t y = 0; y < kChunkSize; ++y)
        for (int32_t x = 0; x < kChunkSize; ++x) {
          const tsdf::Voxel v = tsdf::unpack(chunk->at(x, y, z));
          if (v.weight == 0) continue;
          const openvdb::Coord ijk(key.x * kChunkSize + x, key.y * kChunkSize + y,
                                   key.z * kChunkSize + z);
          // Computed in double, then one rounding to float.
          tsdf_access.setValueOn(ijk, static_cast<float>(v.value * tau / tsdf::kValueScale));
          weight_access.setValueOn(
              ijk, static_cast<float>(static_cast<double>(v.weight) / tsdf::kWeightScale));
          ++stats.active_voxels;
        }
  }
  try {
    openvdb::io::File file(vdb_path.string());
    file.write({tsdf, weight});
    file.close();
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error("cannot write " + vdb_path.string() + ": " + e.what());
  }
  return stats;
}

MapMetadata read_vdb_metadata(const std::filesystem::path& vdb_path) {
  openvdb::initialize();
  openvdb::GridBase::Ptr tsdf;
  try {
    openvdb::io::File file(vdb_path.string());
    file.open();
    if (!file.hasGrid("tsdf") || !file.hasGrid("weight"))
      throw std::runtime_error("no float grids 'tsdf' and 'weight' in " + vdb_path.string());
    tsdf = file.readGridMetadata("tsdf");
    file.close();
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error("cannot read " + vdb_path.string() + ": " + e.what());
  }
  const auto tau_meta = tsdf->getMetadata<openvdb::DoubleMetadata>(kTruncationKey);
  if (!tau_meta)
    throw std::runtime_error("grid 'tsdf' has no truncation_m metadata: " + vdb_path.string());
  MapMetadata metadata;
  metadata.voxel_size_m = tsdf->voxelSize()[0];
  metadata.truncation_m = tau_meta->value();
  return metadata;
}

VdbExportStats import_vdb(const std::filesystem::path& vdb_path, ChunkStore& store) {
  openvdb::initialize();
  openvdb::FloatGrid::Ptr tsdf;
  openvdb::FloatGrid::Ptr weight;
  try {
    openvdb::io::File file(vdb_path.string());
    file.open();
    tsdf = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("tsdf"));
    weight = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("weight"));
    file.close();
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error("cannot read " + vdb_path.string() + ": " + e.what());
  }
  if (!tsdf || !weight)
    throw std::runtime_error("no float grids 'tsdf' and 'weight' in " + vdb_path.string());
  const MapMetadata& metadata = store.metadata();
  const double voxel_size_m = tsdf->voxelSize()[0];
  const auto tau_meta = tsdf->getMetadata<openvdb::DoubleMetadata>(kTruncationKey);
  if (!tau_meta)
    throw std::runtime_error("grid 'tsdf' has no truncation_m metadata: " + vdb_path.string());
  const double tau = tau_meta->value();
  if (!same_length(voxel_size_m, metadata.voxel_size_m) || !same_length(tau, metadata.truncation_m))
    throw std::runtime_error("cannot import " + vdb_path.string() + ": voxel size " +
                             describe(voxel_size_m) + " and tau " + describe(tau) +
                             ", the map has " + describe(metadata.voxel_size_m) + " and " +
                             describe(metadata.truncation_m));

  std::map<ChunkKey, Chunk> chunks;
  VdbExportStats stats;
  auto weight_access = weight->getConstAccessor();
  for (auto it = tsdf->cbeginValueOn(); it; ++it) {
    const openvdb::Coord ijk = it.getCoord();
    const double w = static_cast<double>(weight_access.getValue(ijk));
    const long weight_fixed = std::lround(w * tsdf::kWeightScale);
    if (weight_fixed <= 0) continue;  // unobserved voxels are not stored
    const long value_fixed = std::lround(static_cast<double>(*it) / tau * tsdf::kValueScale);
    tsdf::Voxel v;
    v.value =
        static_cast<int16_t>(std::clamp<long>(value_fixed, -tsdf::kValueScale, tsdf::kValueScale));
    v.weight = static_cast<uint16_t>(std::min<long>(weight_fixed, 0xFFFF));
    const ChunkKey key = chunk_of_voxel(ijk.x(), ijk.y(), ijk.z());
    chunks[key].at(ijk.x() - key.x * kChunkSize, ijk.y() - key.y * kChunkSize,
                   ijk.z() - key.z * kChunkSize) = tsdf::pack(v);
    ++stats.active_voxels;
  }
  for (const auto& [key, chunk] : chunks) store.write(key, chunk);
  stats.chunks = chunks.size();
  return stats;
}

}  // namespace featsense::storage
