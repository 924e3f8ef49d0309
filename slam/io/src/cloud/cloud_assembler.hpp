#pragma once
// Builds a DecodedCloud from the values the PCD and PLY decoders read, field by field: which
// field feeds what (point_fields.hpp), the checks every format shares, and the finishing
// (time units, ring direction).

#include <cstddef>
#include <string>
#include <vector>

#include "cloud/scalar_type.hpp"
#include "featsense/slam/io/cloud_files.hpp"
#include "featsense/slam/io/point_fields.hpp"

namespace featsense::slam::cloud {

/// One field of a file's point record.
struct FileField {
  std::string name;
  ScalarType type = ScalarType::kF32;
  size_t count = 1;  ///< values per point; fields with more than one are skipped
};

class CloudAssembler {
 public:
  /// Checks the fields (x, y and z once each, with one value per point; floating point
  /// when `require_float_xyz`) and sizes the cloud for `points` points. The caller has
  /// already checked that the file holds that many. Throws InputError naming `origin`.
  CloudAssembler(const std::vector<FileField>& fields, size_t points, const std::string& origin,
                 bool require_float_xyz);

  /// Whether field `f` feeds the cloud; decoders need not load the others.
  bool used(size_t f) const { return slots_[f].role != FieldRole::kOther; }
  /// Stores the value of field `f` (a used one) for point `i`.
  void set(size_t i, size_t f, double value);
  /// Stores field `f` (a used one) of every point at once, point i's value read at
  /// src + i * stride: the fast path of fixed-size binary records.
  void set_column(size_t f, const uint8_t* src, size_t stride, ScalarType type, ByteOrder order);

  /// The cloud with times as offsets (point_fields.hpp) and the ring direction measured.
  DecodedCloud finish(std::string format, int width, int height);

  /// Kept in the decoded cloud's warnings.
  void warn(std::string message) { warnings_.push_back(std::move(message)); }

 private:
  struct Slot {
    FieldRole role = FieldRole::kOther;
    size_t channel = 0;  ///< index into cloud_.channels for kChannel
  };
  std::vector<Slot> slots_;
  std::vector<std::string> names_;
  PointCloud cloud_;
  std::vector<double> stored_ring_;  ///< as stored; whole numbers become cloud_.ring
  std::vector<double> stored_time_;
  bool integer_time_ = false;
  std::vector<std::string> warnings_;
};

/// Whether the rings of `cloud` count up (ring 0 lowest, Velodyne) judged by the mean
/// elevation of its lowest and highest rings; true when that cannot be told.
bool rings_count_up(const PointCloud& cloud);

}  // namespace featsense::slam::cloud
