#include "cloud/cloud_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "point_validity.hpp"

namespace featsense::slam::cloud {
namespace {

/// Ring values beyond this are not beam numbers (no LiDAR has this many beams).
constexpr double kMaxRing = 65535.0;

int ring_of(double value) {
  if (!std::isfinite(value) || value < 0.0 || value > kMaxRing) return -1;
  const double whole = std::round(value);
  return whole == value ? static_cast<int>(whole) : -1;
}

}  // namespace

CloudAssembler::CloudAssembler(const std::vector<FileField>& fields, size_t points,
                               const std::string& origin, bool require_float_xyz)
    : slots_(fields.size()) {
  bool seen[3] = {false, false, false};
  bool seen_ring = false, seen_time = false, seen_range = false;
  for (size_t f = 0; f < fields.size(); ++f) {
    const FileField& field = fields[f];
    names_.push_back(field.name);
    const FieldMeaning meaning = classify_field(field.name);
    const bool is_xyz = meaning.role == FieldRole::kX || meaning.role == FieldRole::kY ||
                        meaning.role == FieldRole::kZ;
    if (is_xyz) {
      const size_t axis = static_cast<size_t>(meaning.role) - static_cast<size_t>(FieldRole::kX);
      if (seen[axis]) throw InputError(origin + ": field '" + field.name + "' appears twice");
      seen[axis] = true;
      if (field.count != 1) {
        throw InputError(origin + ": field '" + field.name + "' must hold one value per point");
      }
      if (require_float_xyz && is_integer(field.type)) {
        throw InputError(origin + ": field '" + field.name +
                         "' must be floating point (TYPE F, SIZE 4 or 8), is " +
                         scalar_name(field.type));
      }
      slots_[f].role = meaning.role;
      continue;
    }
    if (meaning.role == FieldRole::kOther || field.count != 1) continue;
    bool* seen_flag = meaning.role == FieldRole::kRing    ? &seen_ring
                      : meaning.role == FieldRole::kTime  ? &seen_time
                      : meaning.role == FieldRole::kRange ? &seen_range
                                                          : nullptr;
    if (seen_flag) {
      if (*seen_flag) {
        warn("second field of the same meaning '" + field.name + "' ignored");
        continue;
      }
      *seen_flag = true;
    }
    slots_[f].role = meaning.role;
    switch (meaning.role) {
      case FieldRole::kRing:
        stored_ring_.assign(points, -1.0);
        break;
      case FieldRole::kTime:
        stored_time_.assign(points, 0.0);
        integer_time_ = is_integer(field.type);
        break;
      case FieldRole::kRange:
        cloud_.range_m.assign(points, 0.0f);
        break;
      case FieldRole::kChannel: {
        const auto existing =
            std::find_if(cloud_.channels.begin(), cloud_.channels.end(),
                         [&](const ScanChannel& c) { return c.name == meaning.channel; });
        if (existing != cloud_.channels.end()) {
          warn("second '" + meaning.channel + "' field '" + field.name + "' ignored");
          slots_[f].role = FieldRole::kOther;
          break;
        }
        slots_[f].channel = cloud_.channels.size();
        cloud_.channels.push_back({meaning.channel, std::vector<float>(points, 0.0f)});
        break;
      }
      default:
        break;
    }
  }
  const char* axes = "xyz";
  for (size_t axis = 0; axis < 3; ++axis) {
    if (!seen[axis]) {
      throw InputError(origin + ": no field '" + std::string(1, axes[axis]) +
                       "' (a point cloud needs x, y and z)");
    }
  }
  cloud_.xyz.assign(points, Eigen::Vector3f::Zero());
}

void CloudAssembler::set(size_t i, size_t f, double value) {
  const Slot& slot = slots_[f];
  switch (slot.role) {
    case FieldRole::kX:
      cloud_.xyz[i].x() = static_cast<float>(value);
      break;
    case FieldRole::kY:
      cloud_.xyz[i].y() = static_cast<float>(value);
      break;
    case FieldRole::kZ:
      cloud_.xyz[i].z() = static_cast<float>(value);
      break;
    case FieldRole::kRing:
      stored_ring_[i] = value;
      break;
    case FieldRole::kTime:
      stored_time_[i] = value;
      break;
    case FieldRole::kRange:
      cloud_.range_m[i] = static_cast<float>(value);
      break;
    case FieldRole::kChannel:
      cloud_.channels[slot.channel].values[i] = static_cast<float>(value);
      break;
    case FieldRole::kOther:
      break;
  }
}

namespace {

constexpr bool kHostLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

/// dst[i * dst_stride] = value of type Stored at src + i * src_stride, for i < n.
template <typename Stored, typename Out>
void copy_column(const uint8_t* src, size_t src_stride, ByteOrder order, size_t n, Out* dst,
                 size_t dst_stride) {
  const bool swap = (order == ByteOrder::kLittle) != kHostLittleEndian;
  for (size_t i = 0; i < n; ++i) {
    uint8_t bytes[sizeof(Stored)];
    std::memcpy(bytes, src + i * src_stride, sizeof(Stored));
    if (swap) std::reverse(bytes, bytes + sizeof(Stored));
    Stored value;
    std::memcpy(&value, bytes, sizeof(Stored));
    dst[i * dst_stride] = static_cast<Out>(value);
  }
}

template <typename Out>
void copy_column(const uint8_t* src, size_t src_stride, ScalarType type, ByteOrder order, size_t n,
                 Out* dst, size_t dst_stride) {
  switch (type) {
    case ScalarType::kI8:
      return copy_column<int8_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kU8:
      return copy_column<uint8_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kI16:
      return copy_column<int16_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kU16:
      return copy_column<uint16_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kI32:
      return copy_column<int32_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kU32:
      return copy_column<uint32_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kI64:
      return copy_column<int64_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kU64:
      return copy_column<uint64_t>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kF32:
      return copy_column<float>(src, src_stride, order, n, dst, dst_stride);
    case ScalarType::kF64:
      return copy_column<double>(src, src_stride, order, n, dst, dst_stride);
  }
}

}  // namespace

void CloudAssembler::set_column(size_t f, const uint8_t* src, size_t stride, ScalarType type,
                                ByteOrder order) {
  const Slot& slot = slots_[f];
  const size_t n = cloud_.xyz.size();
  if (n == 0) return;
  switch (slot.role) {
    case FieldRole::kX:
    case FieldRole::kY:
    case FieldRole::kZ: {
      // Vector3f is three packed floats: component k of point i at data()[3 i + k].
      const size_t axis = static_cast<size_t>(slot.role) - static_cast<size_t>(FieldRole::kX);
      copy_column(src, stride, type, order, n, cloud_.xyz[0].data() + axis, 3);
      break;
    }
    case FieldRole::kRing:
      copy_column(src, stride, type, order, n, stored_ring_.data(), 1);
      break;
    case FieldRole::kTime:
      copy_column(src, stride, type, order, n, stored_time_.data(), 1);
      break;
    case FieldRole::kRange:
      copy_column(src, stride, type, order, n, cloud_.range_m.data(), 1);
      break;
    case FieldRole::kChannel:
      copy_column(src, stride, type, order, n, cloud_.channels[slot.channel].values.data(), 1);
      break;
    case FieldRole::kOther:
      break;
  }
}

DecodedCloud CloudAssembler::finish(std::string format, int width, int height) {
  DecodedCloud decoded;
  decoded.format = std::move(format);
  decoded.width = width;
  decoded.height = height;
  decoded.fields = std::move(names_);
  decoded.warnings = std::move(warnings_);
  if (!stored_time_.empty()) {
    PointTimes times = point_times_to_offsets(stored_time_, integer_time_);
    cloud_.time_offset_s = std::move(times.offset_s);
    decoded.stamp_ns = times.absolute_stamp_ns;
    std::vector<double>().swap(stored_time_);
  }
  if (!stored_ring_.empty()) {
    cloud_.ring.resize(stored_ring_.size());
    std::transform(stored_ring_.begin(), stored_ring_.end(), cloud_.ring.begin(), ring_of);
    std::vector<double>().swap(stored_ring_);
    // Organized clouds place points by row, not ring: no need to measure the direction.
    if (height <= 1) cloud_.ring_counts_up = rings_count_up(cloud_);
  }
  decoded.cloud = std::move(cloud_);
  return decoded;
}

bool rings_count_up(const PointCloud& cloud) {
  int lowest = std::numeric_limits<int>::max();
  int highest = -1;
  for (size_t i = 0; i < cloud.ring.size(); ++i) {
    if (cloud.ring[i] < 0 || !is_return(cloud.xyz[i])) continue;
    lowest = std::min(lowest, cloud.ring[i]);
    highest = std::max(highest, cloud.ring[i]);
  }
  if (highest <= lowest) return true;
  double sum[2] = {0.0, 0.0};
  size_t count[2] = {0, 0};
  for (size_t i = 0; i < cloud.ring.size(); ++i) {
    const int ring = cloud.ring[i];
    if ((ring != lowest && ring != highest) || !is_return(cloud.xyz[i])) continue;
    const Eigen::Vector3d p = cloud.xyz[i].cast<double>();
    const size_t k = ring == highest ? 1 : 0;
    sum[k] += std::atan2(p.z(), std::hypot(p.x(), p.y()));
    ++count[k];
  }
  const double mean_lowest = sum[0] / static_cast<double>(count[0]);
  const double mean_highest = sum[1] / static_cast<double>(count[1]);
  return !(mean_highest < mean_lowest);
}

}  // namespace featsense::slam::cloud
