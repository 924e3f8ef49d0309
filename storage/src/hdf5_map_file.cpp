#include "hdf5_map_file.hpp"

#include <hdf5.h>

#include <array>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "file_ops.hpp"
#include "hdf5_helpers.hpp"

namespace featsense::storage::detail {

static_assert(std::is_same_v<hid_t, int64_t>, "hid_t is carried as int64_t in the header");

namespace {

/// HDF5's own error stack printing is switched off: every failure becomes an exception here.
void silence_hdf5() {
  static const bool once = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)once;
}

}  // namespace

std::string chunk_name(const ChunkKey& key) {
  return std::to_string(key.x) + "_" + std::to_string(key.y) + "_" + std::to_string(key.z);
}

std::optional<ChunkKey> parse_chunk_name(const std::string& name) {
  ChunkKey key;
  int consumed = 0;
  if (std::sscanf(name.c_str(), "%d_%d_%d%n", &key.x, &key.y, &key.z, &consumed) != 3 ||
      static_cast<std::size_t>(consumed) != name.size() || chunk_name(key) != name)
    return std::nullopt;
  return key;
}

Hdf5MapReader::Hdf5MapReader(const std::filesystem::path& path) : path_(path) {
  silence_hdf5();
  if (!std::filesystem::exists(path)) fail("map file does not exist", path);
  if (H5Fis_hdf5(path.c_str()) <= 0) fail("not an HDF5 file, or a truncated one", path);
  file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file_ < 0) fail("cannot open the HDF5 file (truncated or damaged?)", path);

  metadata_.format_version =
      read_number_attribute<int32_t>(file_, "format_version", H5T_NATIVE_INT32, path);
  if (metadata_.format_version < kOldestReadFormatVersion ||
      metadata_.format_version > kFormatVersion)
    fail("map format version " + std::to_string(metadata_.format_version) +
             ", this program reads versions " + std::to_string(kOldestReadFormatVersion) + " to " +
             std::to_string(kFormatVersion),
         path);
  metadata_.voxel_size_m =
      read_number_attribute<double>(file_, "voxel_size_m", H5T_NATIVE_DOUBLE, path);
  metadata_.truncation_m =
      read_number_attribute<double>(file_, "truncation_m", H5T_NATIVE_DOUBLE, path);
  metadata_.value_scale =
      read_number_attribute<int32_t>(file_, "value_scale", H5T_NATIVE_INT32, path);
  metadata_.weight_scale =
      read_number_attribute<int32_t>(file_, "weight_scale", H5T_NATIVE_INT32, path);
  metadata_.chunk_size =
      read_number_attribute<int32_t>(file_, "chunk_size", H5T_NATIVE_INT32, path);
  metadata_.max_weight =
      read_number_attribute<double>(file_, "max_weight", H5T_NATIVE_DOUBLE, path);
  metadata_.sensor = read_string_attribute(file_, "sensor", path);
  metadata_.config_yaml = read_string_attribute(file_, "config_yaml", path);
  if (metadata_.chunk_size != kChunkSize)
    fail("map chunk size " + std::to_string(metadata_.chunk_size) + ", expected " +
             std::to_string(kChunkSize),
         path);

  Handle chunks(H5Gopen2(file_, "/chunks", H5P_DEFAULT), H5Gclose);
  if (!chunks.valid()) fail("not a featsense map: group /chunks is missing", path);
  for (const std::string& name : member_names(chunks.get(), "/chunks", path)) {
    const auto key = parse_chunk_name(name);
    if (!key) fail("unexpected object /chunks/" + name + " (names are x_y_z)", path);
    keys_.push_back(*key);
  }
}

Hdf5MapReader::~Hdf5MapReader() {
  if (file_ >= 0) H5Fclose(file_);
}

Chunk Hdf5MapReader::read(const ChunkKey& key) const {
  const std::string name = "/chunks/" + chunk_name(key);
  Handle dataset(H5Dopen2(file_, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dataset.valid()) fail("cannot open chunk dataset " + name, path_);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  Handle type(H5Dget_type(dataset.get()), H5Tclose);
  std::array<hsize_t, 3> dims{};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  const bool shape_ok = rank == 3 &&
                        H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) == 3 &&
                        dims[0] == kChunkSize && dims[1] == kChunkSize && dims[2] == kChunkSize;
  const bool type_ok = H5Tget_class(type.get()) == H5T_INTEGER && H5Tget_size(type.get()) == 4 &&
                       H5Tget_sign(type.get()) == H5T_SGN_NONE;
  if (!shape_ok || !type_ok)
    fail(
        "chunk dataset " + name + " is not uint32 [64][64][64] (rank " + std::to_string(rank) + ")",
        path_);
  Chunk chunk;
  if (H5Dread(dataset.get(), H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT,
              chunk.voxels.data()) < 0)
    fail("cannot read chunk dataset " + name + " (damaged?)", path_);
  return chunk;
}

std::vector<TrajectoryPose> Hdf5MapReader::read_trajectory() const {
  std::vector<TrajectoryPose> poses;
  if (H5Lexists(file_, "/trajectory", H5P_DEFAULT) <= 0 ||
      H5Lexists(file_, "/trajectory/poses", H5P_DEFAULT) <= 0)
    return poses;
  Handle dataset(H5Dopen2(file_, "/trajectory/poses", H5P_DEFAULT), H5Dclose);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  std::array<hsize_t, 2> dims{};
  if (H5Sget_simple_extent_ndims(space.get()) != 2 ||
      H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) != 2 || dims[1] != 8)
    fail("/trajectory/poses is not N x 8", path_);
  static_assert(sizeof(TrajectoryPose) == 8 * sizeof(double), "a pose is 8 doubles");
  poses.resize(dims[0]);
  if (!poses.empty() &&
      H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, poses.data()) < 0)
    fail("cannot read /trajectory/poses", path_);
  return poses;
}

Hdf5MapWriter::Hdf5MapWriter(const std::filesystem::path& path, const MapMetadata& metadata,
                             int deflate_level)
    : path_(path), deflate_level_(deflate_level) {
  silence_hdf5();
  file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) fail("cannot create the map file (directory missing or not writable?)", path);
  // Always this program's version: a continued older map is rewritten in today's layout.
  const int32_t version = kFormatVersion;
  write_attribute(file_, "format_version", H5T_STD_I32LE, H5T_NATIVE_INT32, &version, path);
  write_attribute(file_, "voxel_size_m", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &metadata.voxel_size_m,
                  path);
  write_attribute(file_, "truncation_m", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &metadata.truncation_m,
                  path);
  write_attribute(file_, "value_scale", H5T_STD_I32LE, H5T_NATIVE_INT32, &metadata.value_scale,
                  path);
  write_attribute(file_, "weight_scale", H5T_STD_I32LE, H5T_NATIVE_INT32, &metadata.weight_scale,
                  path);
  write_attribute(file_, "chunk_size", H5T_STD_I32LE, H5T_NATIVE_INT32, &metadata.chunk_size, path);
  write_attribute(file_, "max_weight", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &metadata.max_weight,
                  path);
  write_string_attribute(file_, "sensor", metadata.sensor, path);
  write_string_attribute(file_, "config_yaml", metadata.config_yaml, path);

  chunks_ = H5Gcreate2(file_, "/chunks", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  Handle trajectory(H5Gcreate2(file_, "/trajectory", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                    H5Gclose);
  Handle keyframes(H5Gcreate2(file_, "/keyframes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                   H5Gclose);
  Handle sessions(H5Gcreate2(file_, "/sessions", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (chunks_ < 0 || !trajectory.valid() || !keyframes.valid() || !sessions.valid())
    fail("cannot create the map's groups", path);

  // One HDF5 chunk per map chunk; shuffle groups the bytes of the weights and values so that
  // deflate finds the runs of equal high bytes.
  dcpl_ = H5Pcreate(H5P_DATASET_CREATE);
  const std::array<hsize_t, 3> dims = {kChunkSize, kChunkSize, kChunkSize};
  if (dcpl_ < 0 || H5Pset_chunk(dcpl_, 3, dims.data()) < 0 || H5Pset_shuffle(dcpl_) < 0 ||
      H5Pset_deflate(dcpl_, static_cast<unsigned>(deflate_level)) < 0)
    fail("cannot set up chunk compression", path);
}

Hdf5MapWriter::~Hdf5MapWriter() {
  if (dcpl_ >= 0) H5Pclose(dcpl_);
  if (chunks_ >= 0) H5Gclose(chunks_);
  if (file_ >= 0) H5Fclose(file_);
}

void Hdf5MapWriter::write_chunk(const ChunkKey& key, const Chunk& chunk) {
  const std::array<hsize_t, 3> dims = {kChunkSize, kChunkSize, kChunkSize};
  Handle space(H5Screate_simple(3, dims.data(), nullptr), H5Sclose);
  const std::string name = chunk_name(key);
  Handle dataset(H5Dcreate2(chunks_, name.c_str(), H5T_STD_U32LE, space.get(), H5P_DEFAULT, dcpl_,
                            H5P_DEFAULT),
                 H5Dclose);
  if (!dataset.valid() || H5Dwrite(dataset.get(), H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                                   chunk.voxels.data()) < 0)
    fail("cannot write chunk " + name + " (disk full?)", path_);
}

void Hdf5MapWriter::copy_chunk(const Hdf5MapReader& source, const ChunkKey& key) {
  const std::string name = chunk_name(key);
  const std::string source_name = "/chunks/" + name;
  if (H5Ocopy(source.handle(), source_name.c_str(), chunks_, name.c_str(), H5P_DEFAULT,
              H5P_DEFAULT) < 0)
    fail("cannot copy chunk " + name + " from " + source.path().string() + " (disk full?)", path_);
}

void Hdf5MapWriter::write_trajectory(const std::vector<TrajectoryPose>& poses) {
  if (poses.empty()) return;
  const std::array<hsize_t, 2> dims = {poses.size(), 8};
  Handle space(H5Screate_simple(2, dims.data(), nullptr), H5Sclose);
  Handle dataset(H5Dcreate2(file_, "/trajectory/poses", H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                            H5P_DEFAULT, H5P_DEFAULT),
                 H5Dclose);
  if (!dataset.valid() ||
      H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, poses.data()) < 0)
    fail("cannot write /trajectory/poses", path_);
  write_string_attribute(dataset.get(), "columns", "t_s x y z qx qy qz qw", path_);
}

void Hdf5MapWriter::close() {
  H5Pclose(dcpl_);
  dcpl_ = -1;
  H5Gclose(chunks_);
  chunks_ = -1;
  const herr_t rc = H5Fclose(file_);
  file_ = -1;
  if (rc < 0) fail("cannot complete the map file (disk full?)", path_);
  sync_file(path_);
}

}  // namespace featsense::storage::detail
