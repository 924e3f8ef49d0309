#include "rosbag/pointcloud2_convert.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

namespace featsense::slam {
namespace {

/// Channel field names and the Scan channel each one fills.
constexpr std::pair<const char*, const char*> kChannelFields[] = {
    {"intensity", "intensity"},
    {"reflectivity", "reflectivity"},
    {"signal", "signal"},
    {"ambient", "ambient"},
    {"nir", "nir"},
    {"near_ir", "nir"},
};
constexpr const char* kTimeFields[] = {"t", "time", "timestamp", "time_stamp", "offset_time"};
constexpr const char* kRingFields[] = {"ring", "channel"};

/// Float times above this are absolute epoch seconds (1e6 s is 11.6 days after 1970).
constexpr double kAbsoluteTimeThresholdS = 1.0e6;
/// Point times further than this from the stamp are taken as garbage.
constexpr double kMaxTimeOffsetS = 3600.0;

/// A float from any field value; doubles beyond float's range become +-infinity instead of
/// an undefined conversion.
template <typename T>
float to_float(T value) {
  if constexpr (std::is_same_v<T, double>) {
    if (value > static_cast<double>(FLT_MAX)) return std::numeric_limits<float>::infinity();
    if (value < -static_cast<double>(FLT_MAX)) return -std::numeric_limits<float>::infinity();
  }
  return static_cast<float>(value);
}

template <typename T, typename Fn>
void visit_typed(const PointCloud2View& cloud, uint32_t offset, Fn&& fn) {
  size_t i = 0;
  for (uint32_t row = 0; row < cloud.height; ++row) {
    for (uint32_t col = 0; col < cloud.width; ++col, ++i) {
      fn(i, load_le<T>(cloud.point(row, col) + offset));
    }
  }
}

/// Calls fn(point index, value) for every point with the field's first element in its own
/// type; the switch on the datatype happens once per field, not per point.
template <typename Fn>
void visit_field(const PointCloud2View& cloud, const PointFieldDesc& field, Fn&& fn) {
  switch (static_cast<PointFieldType>(field.datatype)) {
    case PointFieldType::kInt8:
      return visit_typed<int8_t>(cloud, field.offset, fn);
    case PointFieldType::kUint8:
      return visit_typed<uint8_t>(cloud, field.offset, fn);
    case PointFieldType::kInt16:
      return visit_typed<int16_t>(cloud, field.offset, fn);
    case PointFieldType::kUint16:
      return visit_typed<uint16_t>(cloud, field.offset, fn);
    case PointFieldType::kInt32:
      return visit_typed<int32_t>(cloud, field.offset, fn);
    case PointFieldType::kUint32:
      return visit_typed<uint32_t>(cloud, field.offset, fn);
    case PointFieldType::kFloat32:
      return visit_typed<float>(cloud, field.offset, fn);
    case PointFieldType::kFloat64:
      return visit_typed<double>(cloud, field.offset, fn);
  }
}

std::vector<float> field_as_floats(const PointCloud2View& cloud, const PointFieldDesc& field) {
  std::vector<float> values(cloud.points());
  visit_field(cloud, field, [&](size_t i, auto value) { values[i] = to_float(value); });
  return values;
}

template <size_t N>
const PointFieldDesc* first_field(const PointCloud2View& cloud, const char* const (&names)[N]) {
  for (const char* name : names) {
    if (const PointFieldDesc* field = cloud.field(name)) return field;
  }
  return nullptr;
}

std::vector<Eigen::Vector3f> read_xyz(const PointCloud2View& cloud) {
  std::vector<Eigen::Vector3f> xyz(cloud.points());
  const char* names[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    visit_field(cloud, *cloud.field(names[axis]),
                [&](size_t i, auto value) { xyz[i][axis] = to_float(value); });
  }
  return xyz;
}

bool is_return(const Eigen::Vector3f& p) { return p.allFinite() && !p.isZero(0.0f); }

float elevation_rad(const Eigen::Vector3f& p) {
  return std::atan2(p.z(), std::hypot(p.x(), p.y()));
}

/// Per-point seconds after the returned stamp (the rules in the header).
struct PointTimes {
  int64_t stamp_ns = 0;
  std::vector<float> offsets_s;
};

PointTimes read_times(const PointCloud2View& cloud, int64_t fallback_stamp_ns) {
  PointTimes times;
  times.stamp_ns = cloud.stamp_ns != 0 ? cloud.stamp_ns : fallback_stamp_ns;
  times.offsets_s.assign(cloud.points(), 0.0f);
  const PointFieldDesc* field = first_field(cloud, kTimeFields);
  if (field == nullptr) return times;

  std::vector<double> offsets(cloud.points(), 0.0);
  const double stamp_s = static_cast<double>(times.stamp_ns) * 1e-9;
  if (point_field_is_float(field->datatype)) {
    visit_field(cloud, *field, [&](size_t i, auto value) {
      const auto seconds = static_cast<double>(value);
      offsets[i] = std::abs(seconds) > kAbsoluteTimeThresholdS ? seconds - stamp_s : seconds;
    });
  } else {
    visit_field(cloud, *field,
                [&](size_t i, auto value) { offsets[i] = static_cast<double>(value) * 1e-9; });
  }
  double earliest = 0.0;
  for (double& offset : offsets) {
    if (!std::isfinite(offset) || std::abs(offset) > kMaxTimeOffsetS) offset = 0.0;
    earliest = std::min(earliest, offset);
  }
  // |earliest| <= an hour, so the shift in ns fits easily.
  const auto shift_ns = static_cast<int64_t>(std::llround(earliest * 1e9));
  times.stamp_ns += shift_ns;
  const double shift_s = static_cast<double>(shift_ns) * 1e-9;
  for (size_t i = 0; i < offsets.size(); ++i) {
    times.offsets_s[i] = static_cast<float>(offsets[i] - shift_s);
  }
  return times;
}

/// Adds every channel field of the cloud to `add(name, values)`.
template <typename Add>
void read_channels(const PointCloud2View& cloud, Add&& add) {
  for (const auto& [field_name, channel_name] : kChannelFields) {
    if (const PointFieldDesc* field = cloud.field(field_name)) {
      add(channel_name, field_as_floats(cloud, *field));
    }
  }
}

}  // namespace

Scan organized_cloud_to_scan(const PointCloud2View& cloud, int64_t fallback_stamp_ns) {
  Scan scan = Scan::allocate(static_cast<int>(cloud.height), static_cast<int>(cloud.width));
  scan.xyz = read_xyz(cloud);
  PointTimes times = read_times(cloud, fallback_stamp_ns);
  scan.stamp_ns = times.stamp_ns;
  scan.time_offset_s = std::move(times.offsets_s);

  std::vector<float> reported_range_m;
  if (const PointFieldDesc* range = cloud.field("range")) {
    reported_range_m = field_as_floats(cloud, *range);
    if (!point_field_is_float(range->datatype)) {
      for (float& r : reported_range_m) r *= 0.001f;  // integer ranges are millimetres
    }
  }
  for (size_t i = 0; i < scan.size(); ++i) {
    if (!is_return(scan.xyz[i])) {
      scan.invalidate(i);
      continue;
    }
    scan.valid[i] = 1;
    const bool has_range = !reported_range_m.empty() && std::isfinite(reported_range_m[i]) &&
                           reported_range_m[i] > 0.0f;
    scan.range_m[i] = has_range ? reported_range_m[i] : scan.xyz[i].norm();
  }
  read_channels(cloud, [&](const char* name, std::vector<float> values) {
    scan.add_channel(name).values = std::move(values);
  });
  return scan;
}

PointCloud cloud_to_points(const PointCloud2View& cloud, int64_t fallback_stamp_ns) {
  PointCloud points;
  points.xyz = read_xyz(cloud);
  PointTimes times = read_times(cloud, fallback_stamp_ns);
  points.stamp_ns = times.stamp_ns;
  if (first_field(cloud, kTimeFields) != nullptr) points.time_offset_s = std::move(times.offsets_s);
  read_channels(cloud, [&](const char* name, std::vector<float> values) {
    points.channels.push_back({name, std::move(values)});
  });

  const PointFieldDesc* ring_field = first_field(cloud, kRingFields);
  if (ring_field == nullptr) return points;
  points.ring.assign(cloud.points(), -1);
  visit_field(cloud, *ring_field, [&](size_t i, auto value) {
    const auto ring = static_cast<double>(value);
    if (ring >= 0.0 && ring < 65536.0) points.ring[i] = static_cast<int>(ring);
  });
  // Velodyne numbers rings from the lowest beam up, Ouster from the highest down: compare
  // the mean elevation of the lowest and the highest ring index present.
  int low_ring = std::numeric_limits<int>::max();
  int high_ring = -1;
  for (int ring : points.ring) {
    if (ring < 0) continue;
    low_ring = std::min(low_ring, ring);
    high_ring = std::max(high_ring, ring);
  }
  if (high_ring <= low_ring) return points;
  double sum[2] = {0.0, 0.0};
  size_t count[2] = {0, 0};
  for (size_t i = 0; i < points.size(); ++i) {
    if (!is_return(points.xyz[i])) continue;
    const int which = points.ring[i] == low_ring ? 0 : points.ring[i] == high_ring ? 1 : -1;
    if (which < 0) continue;
    sum[which] += static_cast<double>(elevation_rad(points.xyz[i]));
    ++count[which];
  }
  if (count[0] > 0 && count[1] > 0) {
    points.ring_counts_up =
        sum[1] / static_cast<double>(count[1]) > sum[0] / static_cast<double>(count[0]);
  }
  return points;
}

const PointFieldDesc* time_field(const PointCloud2View& cloud) {
  return first_field(cloud, kTimeFields);
}

int ring_count(const PointCloud2View& cloud) {
  const PointFieldDesc* field = first_field(cloud, kRingFields);
  if (field == nullptr) return 0;
  int count = 0;
  visit_field(cloud, *field, [&](size_t, auto value) {
    const auto ring = static_cast<double>(value);
    if (ring >= 0.0 && ring < 65536.0) count = std::max(count, static_cast<int>(ring) + 1);
  });
  return count;
}

std::vector<std::optional<double>> row_elevations(const Scan& scan) {
  std::vector<std::optional<double>> means(static_cast<size_t>(scan.rows));
  for (int row = 0; row < scan.rows; ++row) {
    double sum = 0.0;
    size_t count = 0;
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      sum += static_cast<double>(elevation_rad(scan.xyz[i]));
      ++count;
    }
    if (count > 0) means[static_cast<size_t>(row)] = sum / static_cast<double>(count);
  }
  return means;
}

std::optional<bool> rows_lowest_first(const Scan& scan) {
  const std::vector<std::optional<double>> means = row_elevations(scan);
  const auto first = std::find_if(means.begin(), means.end(), [](auto m) { return m.has_value(); });
  const auto last =
      std::find_if(means.rbegin(), means.rend(), [](auto m) { return m.has_value(); });
  if (first == means.end() || first == last.base() - 1) return std::nullopt;
  return **first < **last;
}

void flip_rows(Scan& scan) {
  auto flip = [&](auto& values) {
    for (int top = 0, bottom = scan.rows - 1; top < bottom; ++top, --bottom) {
      std::swap_ranges(values.begin() + static_cast<std::ptrdiff_t>(scan.index(top, 0)),
                       values.begin() + static_cast<std::ptrdiff_t>(scan.index(top + 1, 0)),
                       values.begin() + static_cast<std::ptrdiff_t>(scan.index(bottom, 0)));
    }
  };
  flip(scan.xyz);
  flip(scan.range_m);
  flip(scan.time_offset_s);
  flip(scan.valid);
  for (ScanChannel& channel : scan.channels) flip(channel.values);
}

}  // namespace featsense::slam
