// Damaged and foreign files give clear errors naming the file, never a crash or wrong data.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <array>
#include <fstream>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

using test::make_chunk;
using test::test_metadata;

/// Opens the map and reads every chunk; returns the error message, or "" when all worked.
std::string open_and_read_all(const std::filesystem::path& path) {
  try {
    Hdf5ChunkStore store(path);
    for (const auto& key : store.keys()) store.read(key);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

std::filesystem::path make_map(const std::string& name, int chunks) {
  const auto path = test::scratch_dir(name) / "map.h5";
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
  for (int i = 0; i < chunks; ++i)
    store.write({i, -i, 2 * i}, make_chunk(static_cast<uint32_t>(i)));
  store.close();
  return path;
}

TEST(MapFileErrors, MissingFile) {
  const auto path = test::scratch_dir("errors_missing") / "map.h5";
  const std::string message = open_and_read_all(path);
  EXPECT_NE(message.find("does not exist"), std::string::npos) << message;
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

TEST(MapFileErrors, TextFileIsNotHdf5) {
  const auto path = test::scratch_dir("errors_text") / "map.h5";
  { std::ofstream(path) << "voxel_size_m: 0.064\n"; }
  const std::string message = open_and_read_all(path);
  EXPECT_NE(message.find("not an HDF5 file"), std::string::npos) << message;
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

TEST(MapFileErrors, TruncatedFile) {
  const auto path = make_map("errors_truncated", 4);
  for (const double fraction : {0.9, 0.5, 0.01}) {
    const auto copy = path.parent_path() / ("cut" + std::to_string(fraction) + ".h5");
    std::filesystem::copy_file(path, copy);
    std::filesystem::resize_file(
        copy, static_cast<std::uintmax_t>(fraction * std::filesystem::file_size(path)));
    const std::string message = open_and_read_all(copy);
    EXPECT_NE(message.find(copy.string()), std::string::npos) << fraction << ": " << message;
  }
}

TEST(MapFileErrors, ForeignHdf5File) {
  const auto path = test::scratch_dir("errors_foreign") / "other.h5";
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  H5Fclose(file);
  const std::string message = open_and_read_all(path);
  EXPECT_NE(message.find("not a featsense map"), std::string::npos) << message;
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

TEST(MapFileErrors, ChunkDatasetOfWrongShape) {
  const auto path = make_map("errors_shape", 1);
  {
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    const std::array<hsize_t, 3> dims = {32, 64, 64};
    const hid_t space = H5Screate_simple(3, dims.data(), nullptr);
    const hid_t dataset = H5Dcreate2(file, "/chunks/5_5_5", H5T_STD_U32LE, space, H5P_DEFAULT,
                                     H5P_DEFAULT, H5P_DEFAULT);
    const std::vector<uint32_t> zeros(32 * 64 * 64, 1u << 16);
    H5Dwrite(dataset, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros.data());
    H5Dclose(dataset);
    H5Sclose(space);
    H5Fclose(file);
  }
  const std::string message = open_and_read_all(path);
  EXPECT_NE(message.find("5_5_5"), std::string::npos) << message;
  EXPECT_NE(message.find("[64][64][64]"), std::string::npos) << message;
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

TEST(MapFileErrors, LeftoverCheckpointCopyIsIgnored) {
  // A crash during a checkpoint leaves map.h5.tmp half written; the map itself is intact.
  const auto path = make_map("errors_leftover", 2);
  { std::ofstream(path.string() + ".tmp") << "half a file"; }
  { Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata()); }
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  EXPECT_EQ(open_and_read_all(path), "");
}

}  // namespace
}  // namespace featsense::storage
