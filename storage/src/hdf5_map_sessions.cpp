// The sessions and keyframes of the .h5 map file (/sessions, /keyframes; FORMAT.md).

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>

#include "hdf5_helpers.hpp"
#include "hdf5_map_file.hpp"
#include "keyframe_records.hpp"

namespace featsense::storage::detail {

namespace {

static_assert(sizeof(TrajectoryPose) == 8 * sizeof(double), "a pose is written as 8 doubles");

constexpr const char* kPoseColumns = "t_s x y z qx qy qz qw";

hid_t open_keyframe_dataset(hid_t file, const std::string& name,
                            const std::filesystem::path& path) {
  const std::string group = name.substr(0, name.rfind('/'));
  if (H5Lexists(file, group.c_str(), H5P_DEFAULT) <= 0 ||
      H5Lexists(file, name.c_str(), H5P_DEFAULT) <= 0)
    fail("keyframe dataset " + name + " is missing", path);
  const hid_t dataset = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  if (dataset < 0) fail("cannot open keyframe dataset " + name, path);
  return dataset;
}

/// The dataset's dimensions (a second one of 1 for rank 1) after checking its element type and
/// rank; the error names the dataset and `expected`, e.g. "int16 [N][3]".
std::array<hsize_t, 2> checked_dims(hid_t dataset, H5T_class_t type_class, std::size_t type_size,
                                    int rank, const std::string& name, const char* expected,
                                    const std::filesystem::path& path) {
  Handle space(H5Dget_space(dataset), H5Sclose);
  Handle type(H5Dget_type(dataset), H5Tclose);
  std::array<hsize_t, 2> dims = {1, 1};
  const bool type_ok = H5Tget_class(type.get()) == type_class &&
                       H5Tget_size(type.get()) == type_size &&
                       (type_class != H5T_INTEGER || H5Tget_sign(type.get()) == H5T_SGN_2);
  const bool rank_ok = H5Sget_simple_extent_ndims(space.get()) == rank &&
                       H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) == rank;
  if (!type_ok || !rank_ok) fail("keyframe dataset " + name + " is not " + expected, path);
  return dims;
}

void read_all(hid_t dataset, hid_t memory_type, void* data, std::size_t count,
              const std::string& name, const std::filesystem::path& path) {
  if (count > 0 && H5Dread(dataset, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    fail("cannot read keyframe dataset " + name + " (damaged?)", path);
}

/// Creates `name` in `group` with the given shape (dimensions may be 0) and writes `data`.
void write_dataset(hid_t group, const char* name, hid_t file_type, hid_t memory_type, int rank,
                   const hsize_t* dims, const void* data, hid_t dcpl, const std::string& group_name,
                   const std::filesystem::path& path) {
  Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose);
  Handle dataset(H5Dcreate2(group, name, file_type, space.get(), H5P_DEFAULT, dcpl, H5P_DEFAULT),
                 H5Dclose);
  std::size_t count = 1;
  for (int i = 0; i < rank; ++i) count *= dims[i];
  if (!dataset.valid() ||
      (count > 0 && H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0))
    fail("cannot write " + group_name + "/" + name + " (disk full?)", path);
}

}  // namespace

std::vector<KeyframeKey> Hdf5MapReader::keyframe_keys() const {
  std::vector<KeyframeKey> keys;
  if (H5Lexists(file_, "/keyframes", H5P_DEFAULT) <= 0) return keys;
  Handle group(H5Gopen2(file_, "/keyframes", H5P_DEFAULT), H5Gclose);
  if (!group.valid()) fail("cannot open /keyframes", path_);
  for (const std::string& name : member_names(group.get(), "/keyframes", path_)) {
    const auto key = parse_keyframe_name(name);
    if (!key)
      fail("unexpected object /keyframes/" + name + " (names are s<session>_k<index>)", path_);
    keys.push_back(*key);
  }
  std::sort(keys.begin(), keys.end());  // names sort "s10" before "s2"
  return keys;
}

StoredKeyframe Hdf5MapReader::read_keyframe(const KeyframeKey& key) const {
  const std::string group = "/keyframes/" + keyframe_name(key);
  StoredKeyframe keyframe;
  keyframe.session = key.session;
  keyframe.index = key.index;
  {
    const std::string name = group + "/pose";
    Handle dataset(open_keyframe_dataset(file_, name, path_), H5Dclose);
    const auto dims = checked_dims(dataset.get(), H5T_FLOAT, 8, 1, name, "float64 [8]", path_);
    if (dims[0] != 8) fail("keyframe dataset " + name + " is not float64 [8]", path_);
    std::array<double, 8> pose{};
    read_all(dataset.get(), H5T_NATIVE_DOUBLE, pose.data(), pose.size(), name, path_);
    if (!std::all_of(pose.begin(), pose.end(), [](double v) { return std::isfinite(v); }))
      fail("keyframe dataset " + name + " holds a value that is not finite", path_);
    keyframe.pose = {pose[0], pose[1], pose[2], pose[3], pose[4], pose[5], pose[6], pose[7]};
  }
  {
    const std::string name = group + "/descriptor";
    Handle dataset(open_keyframe_dataset(file_, name, path_), H5Dclose);
    const auto dims =
        checked_dims(dataset.get(), H5T_FLOAT, 4, 2, name, "float32 [rows][cols]", path_);
    if (dims[0] > UINT16_MAX || dims[1] > UINT16_MAX)
      fail("keyframe dataset " + name + " has more than 65535 rows or columns", path_);
    keyframe.descriptor_rows = static_cast<uint16_t>(dims[0]);
    keyframe.descriptor_cols = static_cast<uint16_t>(dims[1]);
    keyframe.descriptor.resize(dims[0] * dims[1]);
    read_all(dataset.get(), H5T_NATIVE_FLOAT, keyframe.descriptor.data(),
             keyframe.descriptor.size(), name, path_);
  }
  {
    const std::string name = group + "/cloud_cm";
    Handle dataset(open_keyframe_dataset(file_, name, path_), H5Dclose);
    const auto dims = checked_dims(dataset.get(), H5T_INTEGER, 2, 2, name, "int16 [N][3]", path_);
    if (dims[1] != 3) fail("keyframe dataset " + name + " is not int16 [N][3]", path_);
    keyframe.cloud_cm.resize(dims[0] * 3);
    read_all(dataset.get(), H5T_NATIVE_INT16, keyframe.cloud_cm.data(), keyframe.cloud_cm.size(),
             name, path_);
  }
  return keyframe;
}

std::vector<MapSession> Hdf5MapReader::read_sessions() const {
  std::vector<MapSession> sessions;
  if (H5Lexists(file_, "/sessions", H5P_DEFAULT) <= 0) return sessions;
  Handle sessions_group(H5Gopen2(file_, "/sessions", H5P_DEFAULT), H5Gclose);
  if (!sessions_group.valid()) fail("cannot open /sessions", path_);
  for (const std::string& member : member_names(sessions_group.get(), "/sessions", path_)) {
    const std::string name = "/sessions/" + member;
    Handle group(H5Gopen2(file_, name.c_str(), H5P_DEFAULT), H5Gclose);
    if (!group.valid()) fail("session " + name + " is not a group", path_);
    for (const char* attribute :
         {"id", "input", "format", "scans", "first_stamp_s", "last_stamp_s", "placement"})
      if (H5Aexists(group.get(), attribute) <= 0)
        fail("session " + name + " lacks the attribute '" + attribute + "'", path_);
    MapSession session;
    session.id = read_number_attribute<uint32_t>(group.get(), "id", H5T_NATIVE_UINT32, path_);
    session.input = read_string_attribute(group.get(), "input", path_);
    session.format = read_string_attribute(group.get(), "format", path_);
    session.scans = read_number_attribute<uint64_t>(group.get(), "scans", H5T_NATIVE_UINT64, path_);
    session.first_stamp_s =
        read_number_attribute<double>(group.get(), "first_stamp_s", H5T_NATIVE_DOUBLE, path_);
    session.last_stamp_s =
        read_number_attribute<double>(group.get(), "last_stamp_s", H5T_NATIVE_DOUBLE, path_);
    session.placement = read_string_attribute(group.get(), "placement", path_);
    if (member != session_name(session.id))
      fail("session " + name + " has the id " + std::to_string(session.id), path_);
    sessions.push_back(std::move(session));
  }
  std::sort(sessions.begin(), sessions.end(),
            [](const MapSession& a, const MapSession& b) { return a.id < b.id; });
  return sessions;
}

void Hdf5MapWriter::write_keyframe(const StoredKeyframe& keyframe) {
  const std::string name = "/keyframes/" + keyframe_name(keyframe.key());
  Handle group(H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (!group.valid()) fail("cannot create " + name + " (disk full?)", path_);
  write_attribute(group.get(), "session", H5T_STD_U32LE, H5T_NATIVE_UINT32, &keyframe.session,
                  path_);
  write_attribute(group.get(), "index", H5T_STD_U32LE, H5T_NATIVE_UINT32, &keyframe.index, path_);

  const hsize_t pose_dims[1] = {8};
  write_dataset(group.get(), "pose", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, pose_dims,
                &keyframe.pose, H5P_DEFAULT, name, path_);
  {
    Handle pose(H5Dopen2(group.get(), "pose", H5P_DEFAULT), H5Dclose);
    write_string_attribute(pose.get(), "columns", kPoseColumns, path_);
  }
  const hsize_t descriptor_dims[2] = {keyframe.descriptor_rows, keyframe.descriptor_cols};
  write_dataset(group.get(), "descriptor", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, 2, descriptor_dims,
                keyframe.descriptor.data(), H5P_DEFAULT, name, path_);

  // The cloud is most of a keyframe: one compressed HDF5 chunk, shuffled so that deflate sees
  // the high bytes of the centimetres together. HDF5 chunks cannot be empty.
  const hsize_t cloud_dims[2] = {keyframe.points(), 3};
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  if (keyframe.points() > 0 &&
      (H5Pset_chunk(dcpl.get(), 2, cloud_dims) < 0 || H5Pset_shuffle(dcpl.get()) < 0 ||
       H5Pset_deflate(dcpl.get(), static_cast<unsigned>(deflate_level_)) < 0))
    fail("cannot set up keyframe cloud compression", path_);
  write_dataset(group.get(), "cloud_cm", H5T_STD_I16LE, H5T_NATIVE_INT16, 2, cloud_dims,
                keyframe.cloud_cm.data(), dcpl.get(), name, path_);
}

void Hdf5MapWriter::copy_keyframe(const Hdf5MapReader& source, const KeyframeKey& key) {
  const std::string name = "/keyframes/" + keyframe_name(key);
  if (H5Ocopy(source.handle(), name.c_str(), file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT) < 0)
    fail("cannot copy " + name + " from " + source.path().string() + " (disk full?)", path_);
}

void Hdf5MapWriter::write_sessions(const std::vector<MapSession>& sessions) {
  for (const MapSession& session : sessions) {
    const std::string name = "/sessions/" + session_name(session.id);
    Handle group(H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (!group.valid()) fail("cannot create " + name + " (disk full?)", path_);
    write_attribute(group.get(), "id", H5T_STD_U32LE, H5T_NATIVE_UINT32, &session.id, path_);
    write_string_attribute(group.get(), "input", session.input, path_);
    write_string_attribute(group.get(), "format", session.format, path_);
    write_attribute(group.get(), "scans", H5T_STD_U64LE, H5T_NATIVE_UINT64, &session.scans, path_);
    write_attribute(group.get(), "first_stamp_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                    &session.first_stamp_s, path_);
    write_attribute(group.get(), "last_stamp_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                    &session.last_stamp_s, path_);
    write_string_attribute(group.get(), "placement", session.placement, path_);
  }
}

}  // namespace featsense::storage::detail
