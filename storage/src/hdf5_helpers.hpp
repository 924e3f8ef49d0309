#pragma once
/// Small helpers over HDF5's C API shared by the map file's readers and writers: handles that
/// close themselves, attributes, and failures that name the file. Only the .cpp files that
/// talk to HDF5 include this header.

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace featsense::storage::detail {

[[noreturn]] inline void fail(const std::string& what, const std::filesystem::path& path) {
  throw std::runtime_error(what + " (" + path.string() + ")");
}

/// Closes an HDF5 identifier when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

inline void write_attribute(hid_t object, const char* name, hid_t file_type, hid_t memory_type,
                            const void* value, const std::filesystem::path& path) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                   H5Aclose);
  if (!attribute.valid() || H5Awrite(attribute.get(), memory_type, value) < 0)
    fail(std::string("cannot write attribute ") + name, path);
}

inline void write_string_attribute(hid_t object, const char* name, const std::string& value,
                                   const std::filesystem::path& path) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  // Fixed length (at least 1: HDF5 has no empty fixed strings), padded with NULs.
  H5Tset_size(type.get(), value.empty() ? 1 : value.size());
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  write_attribute(object, name, type.get(), type.get(), padded.data(), path);
}

/// The attribute's identifier (the caller closes it); throws when it is missing.
inline hid_t open_attribute(hid_t object, const char* name, const std::filesystem::path& path) {
  if (H5Aexists(object, name) <= 0)
    fail(std::string("not a featsense map: attribute '") + name + "' is missing", path);
  const hid_t attribute = H5Aopen(object, name, H5P_DEFAULT);
  if (attribute < 0) fail(std::string("cannot open attribute ") + name, path);
  return attribute;
}

template <typename T>
T read_number_attribute(hid_t object, const char* name, hid_t memory_type,
                        const std::filesystem::path& path) {
  Handle attribute(open_attribute(object, name, path), H5Aclose);
  T value{};
  if (H5Aread(attribute.get(), memory_type, &value) < 0)
    fail(std::string("cannot read attribute ") + name, path);
  return value;
}

inline std::string read_string_attribute(hid_t object, const char* name,
                                         const std::filesystem::path& path) {
  Handle attribute(open_attribute(object, name, path), H5Aclose);
  Handle type(H5Aget_type(attribute.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) > 0)
    fail(std::string("attribute ") + name + " is not a fixed-length string", path);
  std::string value(H5Tget_size(type.get()), '\0');
  if (H5Aread(attribute.get(), type.get(), value.data()) < 0)
    fail(std::string("cannot read attribute ") + name, path);
  value.resize(
      value.find_last_not_of('\0') == std::string::npos ? 0 : value.find_last_not_of('\0') + 1);
  return value;
}

/// The names of a group's members, in name order.
inline std::vector<std::string> member_names(hid_t group, const std::string& group_name,
                                             const std::filesystem::path& path) {
  H5G_info_t info;
  if (H5Gget_info(group, &info) < 0) fail("cannot list " + group_name, path);
  std::vector<std::string> names;
  names.reserve(info.nlinks);
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t length =
        H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (length < 0) fail("cannot list " + group_name, path);
    std::string name(static_cast<std::size_t>(length) + 1, '\0');
    H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(),
                       H5P_DEFAULT);
    name.resize(static_cast<std::size_t>(length));
    names.push_back(std::move(name));
  }
  return names;
}

}  // namespace featsense::storage::detail
