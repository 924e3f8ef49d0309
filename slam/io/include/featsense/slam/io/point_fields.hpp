#pragma once
/// What a point field's name means, shared by the readers of self-describing clouds (PCD,
/// PLY, ROS PointCloud2), and how stored per-point times become offsets in seconds.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace featsense::slam {

enum class FieldRole { kX, kY, kZ, kRing, kTime, kRange, kChannel, kOther };

struct FieldMeaning {
  FieldRole role = FieldRole::kOther;
  std::string channel;  ///< the Scan channel name for kChannel ("intensity", "nir", ...)
};

/// Case-insensitive: `x` `y` `z`; `ring` / `channel` (beam index); `t` / `time` / `timestamp`
/// / `time_stamp` (per-point time); `range` / `distance` (the sensor's range, metres);
/// `intensity` `reflectivity` `signal` `ambient` `nir` (`near_ir` becomes `nir`) are kept as
/// channels. Anything else (azimuth, return_type, padding `_`, ...) is kOther.
FieldMeaning classify_field(std::string_view name);

/// The channel names classify_field() keeps, in a fixed order.
const std::vector<std::string>& known_channel_names();

/// Per-point times turned into offsets after the scan's stamp.
struct PointTimes {
  std::vector<float> offset_s;
  /// Set when the stored times were absolute (since 1970): the earliest of them, which the
  /// offsets are measured from.
  std::optional<int64_t> absolute_stamp_ns;
};

/// Converts stored time values to offsets in seconds. Units: integer fields count
/// nanoseconds (Ouster `t`: u32 ns since the frame start); floating-point fields count seconds
/// (Velodyne `time`), except values above 1e15, which only nanoseconds since 1970 reach.
/// Times above 1e8 s (after 1973) are absolute: they become offsets from the earliest one,
/// returned as absolute_stamp_ns (double precision: within ~0.3 us). Non-finite values, and
/// offsets beyond float's range, become 0.
PointTimes point_times_to_offsets(const std::vector<double>& stored, bool integer_field);

}  // namespace featsense::slam
