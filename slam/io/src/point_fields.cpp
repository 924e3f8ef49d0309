// Field names of self-describing point clouds and the units of their per-point times.

#include "featsense/slam/io/point_fields.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

namespace featsense::slam {
namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Floating-point times above this are nanoseconds: seconds since 1970 stay near 2e9.
constexpr double kFloatNanosecondsAbove = 1e15;
/// Times later than this (in seconds; early 1973) are absolute, not offsets in a scan.
constexpr double kAbsoluteSecondsAbove = 1e8;

}  // namespace

const std::vector<std::string>& known_channel_names() {
  static const std::vector<std::string> kNames = {"intensity", "reflectivity", "signal", "ambient",
                                                  "nir"};
  return kNames;
}

FieldMeaning classify_field(std::string_view name) {
  const std::string key = lower(name);
  if (key == "x") return {FieldRole::kX, {}};
  if (key == "y") return {FieldRole::kY, {}};
  if (key == "z") return {FieldRole::kZ, {}};
  if (key == "ring" || key == "channel") return {FieldRole::kRing, {}};
  if (key == "t" || key == "time" || key == "timestamp" || key == "time_stamp") {
    return {FieldRole::kTime, {}};
  }
  if (key == "range" || key == "distance") return {FieldRole::kRange, {}};
  if (key == "near_ir") return {FieldRole::kChannel, "nir"};
  const auto& channels = known_channel_names();
  if (std::find(channels.begin(), channels.end(), key) != channels.end()) {
    return {FieldRole::kChannel, key};
  }
  return {FieldRole::kOther, {}};
}

PointTimes point_times_to_offsets(const std::vector<double>& stored, bool integer_field) {
  double max_abs = 0.0;
  for (double v : stored) {
    if (std::isfinite(v)) max_abs = std::max(max_abs, std::abs(v));
  }
  const bool nanoseconds = integer_field || max_abs > kFloatNanosecondsAbove;
  const double to_seconds = nanoseconds ? 1e-9 : 1.0;

  double earliest = std::numeric_limits<double>::infinity();
  for (double v : stored) {
    if (std::isfinite(v)) earliest = std::min(earliest, v);
  }
  PointTimes times;
  double origin = 0.0;
  if (std::isfinite(earliest) && earliest * to_seconds > kAbsoluteSecondsAbove) {
    origin = earliest;
    times.absolute_stamp_ns = static_cast<int64_t>(std::llround(earliest * to_seconds * 1e9));
  }
  times.offset_s.reserve(stored.size());
  for (double v : stored) {
    // Offsets beyond float's range (garbage, not times) become 0 like non-finite ones.
    const float offset = static_cast<float>((v - origin) * to_seconds);
    times.offset_s.push_back(std::isfinite(offset) ? offset : 0.0f);
  }
  return times;
}

}  // namespace featsense::slam
