// Damaged and foreign files give clear errors naming the file, never a crash or wrong data;
// files of the previous format version still read.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

using test::make_chunk;
using test::make_keyframe;
using test::make_session;
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

/// A map with two keyframes of session 0 in its .h5.
std::filesystem::path make_map_with_keyframes(const std::string& name) {
  const auto path = test::scratch_dir(name) / "map.h5";
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
  store.write({0, 0, 0}, make_chunk(1));
  store.write_sessions({make_session(0, "first session")});
  store.write_keyframes({make_keyframe(0, 0), make_keyframe(0, 1, 40)});
  store.close();
  return path;
}

/// Edits the map file in place through HDF5's C API.
void edit_map(const std::filesystem::path& path, const std::function<void(hid_t)>& edit) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  edit(file);
  H5Fclose(file);
}

/// Replaces the dataset `name` by one of `type` and shape `dims`, filled with zeros.
void replace_dataset(hid_t file, const std::string& name, hid_t type,
                     const std::vector<hsize_t>& dims) {
  H5Ldelete(file, name.c_str(), H5P_DEFAULT);
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t dataset =
      H5Dcreate2(file, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  std::size_t count = 1;
  for (const hsize_t d : dims) count *= d;
  const std::vector<double> zeros(count, 0.0);
  H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros.data());
  H5Dclose(dataset);
  H5Sclose(space);
}

/// Opens the map and reads its keyframes and sessions; the error message, or "".
std::string open_and_read_keyframes(const std::filesystem::path& path) {
  try {
    Hdf5ChunkStore store(path);
    store.read_keyframes();
    store.read_sessions();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(MapFileErrors, KeyframeDatasetsOfWrongTypeOrShape) {
  struct Case {
    const char* name;
    std::function<void(hid_t)> edit;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"cloud_float",
       [](hid_t f) {
         replace_dataset(f, "/keyframes/s0_k1/cloud_cm", H5T_IEEE_F32LE, {40, 3});
       },
       "/keyframes/s0_k1/cloud_cm is not int16 [N][3]"},
      {"cloud_columns",
       [](hid_t f) {
         replace_dataset(f, "/keyframes/s0_k1/cloud_cm", H5T_STD_I16LE, {40, 2});
       },
       "/keyframes/s0_k1/cloud_cm is not int16 [N][3]"},
      {"cloud_unsigned",
       [](hid_t f) {
         replace_dataset(f, "/keyframes/s0_k0/cloud_cm", H5T_STD_U16LE, {9, 3});
       },
       "/keyframes/s0_k0/cloud_cm is not int16 [N][3]"},
      {"descriptor_rank",
       [](hid_t f) { replace_dataset(f, "/keyframes/s0_k0/descriptor", H5T_IEEE_F32LE, {1200}); },
       "/keyframes/s0_k0/descriptor is not float32 [rows][cols]"},
      {"descriptor_double",
       [](hid_t f) {
         replace_dataset(f, "/keyframes/s0_k0/descriptor", H5T_IEEE_F64LE, {20, 60});
       },
       "/keyframes/s0_k0/descriptor is not float32 [rows][cols]"},
      {"pose_short",
       [](hid_t f) { replace_dataset(f, "/keyframes/s0_k1/pose", H5T_IEEE_F64LE, {7}); },
       "/keyframes/s0_k1/pose is not float64 [8]"},
      {"pose_missing", [](hid_t f) { H5Ldelete(f, "/keyframes/s0_k1/pose", H5P_DEFAULT); },
       "/keyframes/s0_k1/pose is missing"},
      {"pose_nan",
       [](hid_t f) {
         const hid_t dataset = H5Dopen2(f, "/keyframes/s0_k0/pose", H5P_DEFAULT);
         const std::array<double, 8> pose = {1, 2, 3, std::nan(""), 0, 0, 0, 1};
         H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pose.data());
         H5Dclose(dataset);
       },
       "/keyframes/s0_k0/pose holds a value that is not finite"},
      {"foreign_member",
       [](hid_t f) {
         H5Gclose(H5Gcreate2(f, "/keyframes/extra", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
       },
       "/keyframes/extra"},
      {"session_attribute",
       [](hid_t f) { H5Adelete_by_name(f, "/sessions/s0", "placement", H5P_DEFAULT); },
       "/sessions/s0 lacks the attribute 'placement'"},
  };
  for (const Case& c : cases) {
    const auto path = make_map_with_keyframes(std::string("errors_keyframe_") + c.name);
    edit_map(path, c.edit);
    const std::string message = open_and_read_keyframes(path);
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.name << ": " << message;
    EXPECT_NE(message.find(path.string()), std::string::npos) << c.name << ": " << message;
  }
}

TEST(MapFileErrors, VersionOneFileReadsAsHavingNoSessions) {
  // What an older program wrote: format version 1, no /sessions, no /keyframes.
  const auto path = make_map("errors_version_one", 2);
  edit_map(path, [](hid_t file) {
    H5Ldelete(file, "/keyframes", H5P_DEFAULT);
    H5Ldelete(file, "/sessions", H5P_DEFAULT);
    const int32_t version = 1;
    const hid_t attribute = H5Aopen(file, "format_version", H5P_DEFAULT);
    H5Awrite(attribute, H5T_NATIVE_INT32, &version);
    H5Aclose(attribute);
  });
  {
    Hdf5ChunkStore store(path);
    EXPECT_EQ(store.metadata().format_version, 1);
    EXPECT_TRUE(store.read_keyframes().empty());
    EXPECT_TRUE(store.read_sessions().empty());
    EXPECT_TRUE(*store.read({1, -1, 2}) == make_chunk(1));
  }
  {
    // Continued, it is rewritten in the current layout at once, before any record of it is
    // journalled: even a crash leaves no new record over a version 1 file.
    StoreSettings no_checkpoint;
    no_checkpoint.checkpoint_on_close = false;
    Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata(), no_checkpoint);
    EXPECT_EQ(store.metadata().format_version, kFormatVersion);
    EXPECT_EQ(Hdf5ChunkStore(path).metadata().format_version, kFormatVersion);
    store.write_sessions({make_session(1, "relocalized")});
    store.write_keyframes({make_keyframe(1, 0)});
  }
  Hdf5ChunkStore store(path);
  EXPECT_EQ(store.metadata().format_version, kFormatVersion);
  ASSERT_EQ(store.read_keyframes().size(), 1u);
  EXPECT_TRUE(test::same_keyframe(store.read_keyframes()[0], make_keyframe(1, 0)));
  EXPECT_EQ(store.read_sessions().size(), 1u);
  EXPECT_EQ(store.keys().size(), 2u);
}

TEST(MapFileErrors, NewerFormatVersionIsRefused) {
  const auto path = make_map("errors_version_three", 1);
  edit_map(path, [](hid_t file) {
    const int32_t version = kFormatVersion + 1;
    const hid_t attribute = H5Aopen(file, "format_version", H5P_DEFAULT);
    H5Awrite(attribute, H5T_NATIVE_INT32, &version);
    H5Aclose(attribute);
  });
  const std::string message = open_and_read_all(path);
  EXPECT_NE(message.find("format version " + std::to_string(kFormatVersion + 1)), std::string::npos)
      << message;
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

}  // namespace
}  // namespace featsense::storage
