// choose_sensor() and cloud_to_scan(): a decoded file's cloud as a Scan of some sensor.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "cloud/sensor_guess.hpp"
#include "featsense/slam/io/azimuth_times.hpp"
#include "featsense/slam/io/cloud_files.hpp"
#include "featsense/slam/io/point_fields.hpp"
#include "featsense/slam/io/readers.hpp"
#include "point_validity.hpp"

namespace featsense::slam {
namespace {

std::string preset_list() {
  std::string list;
  for (const std::string& name : config::sensor_preset_names()) {
    list += (list.empty() ? "" : ", ") + name;
  }
  return list;
}

/// Per-point times shorter than this share of a revolution, spread over at least half of
/// the columns, cannot be times within the revolution.
constexpr double kMinTimeSpanRevolutions = 0.25;
constexpr double kMaxTimeSpanRevolutions = 2.0;

/// Drops per-point times that cannot be offsets within this revolution, says why, and
/// returns whether it dropped them. Offsets may be negative (a stamp mid-sweep): only their
/// span counts.
bool check_times(Scan& scan, double rate_hz, const std::string& origin,
                 std::vector<std::string>* warnings) {
  float earliest = std::numeric_limits<float>::infinity();
  float latest = -earliest;
  std::vector<char> column_used(static_cast<size_t>(scan.cols), 0);
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      const size_t i = scan.index(r, c);
      if (!scan.valid[i]) continue;
      earliest = std::min(earliest, scan.time_offset_s[i]);
      latest = std::max(latest, scan.time_offset_s[i]);
      column_used[static_cast<size_t>(c)] = 1;
    }
  }
  if (!(latest >= earliest) || scan.cols == 0) return false;
  const double span_s = static_cast<double>(latest) - static_cast<double>(earliest);
  const double revolution_s = 1.0 / rate_hz;
  const double columns_used =
      static_cast<double>(std::count(column_used.begin(), column_used.end(), 1)) /
      static_cast<double>(scan.cols);
  const bool too_short = columns_used >= 0.5 && span_s < kMinTimeSpanRevolutions * revolution_s;
  const bool too_long = span_s > kMaxTimeSpanRevolutions * revolution_s;
  if (!too_short && !too_long) return false;
  if (span_s == 0.0) return false;  // no times at all: nothing to drop
  std::fill(scan.time_offset_s.begin(), scan.time_offset_s.end(), 0.0f);
  if (warnings) {
    warnings->push_back(origin + ": per-point times span " + std::to_string(span_s * 1e3) +
                        " ms over " + std::to_string(static_cast<int>(columns_used * 100)) +
                        " % of the columns, " +
                        (too_short ? "far less than a revolution of " : "more than two of ") +
                        std::to_string(revolution_s * 1e3) + " ms: not times within the scan" +
                        (too_short ? " (per packet?)" : " (other units?)") + "; set to 0");
  }
  return true;
}

/// The file's field that gave the per-point times: the first of time meaning, as the
/// decoders take it.
std::string time_field_name(const DecodedCloud& decoded) {
  for (const std::string& name : decoded.fields) {
    if (classify_field(name).role == FieldRole::kTime) return name;
  }
  return "time";
}

/// `times`: per cell, from the file or the azimuth; empty for none.
Scan organized_to_scan(const DecodedCloud& decoded, const std::vector<float>& times,
                       const std::string& origin, OrganizeStats* stats) {
  const PointCloud& cloud = decoded.cloud;
  const size_t cells = static_cast<size_t>(decoded.height) * static_cast<size_t>(decoded.width);
  auto fits = [cells](size_t n) { return n == 0 || n == cells; };
  bool consistent = cloud.size() == cells && fits(times.size()) && fits(cloud.range_m.size());
  for (const ScanChannel& c : cloud.channels) consistent = consistent && c.values.size() == cells;
  if (!consistent) {
    throw InputError(origin + ": an organized cloud of " + std::to_string(decoded.height) + " x " +
                     std::to_string(decoded.width) + " with " + std::to_string(cloud.size()) +
                     " points (or per-point fields of another length)");
  }
  Scan scan = Scan::allocate(decoded.height, decoded.width);
  for (const ScanChannel& c : cloud.channels) scan.add_channel(c.name).values = c.values;
  const bool has_time = !times.empty();
  const bool has_range = !cloud.range_m.empty();
  OrganizeStats counts;
  counts.input_points = cloud.size();
  for (size_t i = 0; i < scan.size(); ++i) {
    // Times and channels of empty cells as the file has them: the cell stays a cell.
    if (has_time) scan.time_offset_s[i] = times[i];
    if (!is_return(cloud.xyz[i])) {
      ++counts.dropped_invalid;
      continue;
    }
    scan.valid[i] = 1;
    scan.xyz[i] = cloud.xyz[i];
    const float range = has_range ? cloud.range_m[i] : 0.0f;
    scan.range_m[i] = std::isfinite(range) && range > 0.0f ? range : return_range(cloud.xyz[i]);
  }
  for (ScanChannel& c : scan.channels) {
    for (float& v : c.values) v = std::isfinite(v) ? v : 0.0f;
  }
  for (float& t : scan.time_offset_s) t = std::isfinite(t) ? t : 0.0f;

  // Row 0 must be the highest beam; some writers start at the lowest.
  if (cloud::lowest_row_first(cloud, decoded.width, decoded.height)) {
    auto swap_rows = [&](auto& values) {
      for (int r = 0; r < scan.rows / 2; ++r) {
        std::swap_ranges(
            values.begin() + static_cast<std::ptrdiff_t>(scan.index(r, 0)),
            values.begin() + static_cast<std::ptrdiff_t>(scan.index(r + 1, 0)),
            values.begin() + static_cast<std::ptrdiff_t>(scan.index(scan.rows - 1 - r, 0)));
      }
    };
    swap_rows(scan.xyz);
    swap_rows(scan.range_m);
    swap_rows(scan.time_offset_s);
    swap_rows(scan.valid);
    for (ScanChannel& c : scan.channels) swap_rows(c.values);
  }
  if (stats) *stats = counts;
  return scan;
}

/// An organized cloud's sensor, from its rows: the preset whose beams the rows lie on; else
/// beam elevations measured from the rows when at least half of them hold points; else the
/// preset with that many beams; else a model from the few rows measured.
config::SensorModel sensor_of_rows(const DecodedCloud& decoded, const SourceOptions& options,
                                   const std::string& origin,
                                   const std::function<void(const std::string&)>& say) {
  auto rows = cloud::row_elevations(decoded.cloud, decoded.width, decoded.height);
  // cloud_to_scan() flips such files; the model describes the flipped rows.
  if (cloud::lowest_row_first(rows)) std::reverse(rows.begin(), rows.end());
  const std::string shape = std::to_string(decoded.height) + " rows";
  if (const auto name = cloud::preset_fitting_rows(rows)) {
    say("preset " + *name + " (the " + shape + " lie on its beams)");
    return sensor_for(options, *name);
  }
  const auto measured = cloud::sensor_from_rows(rows, decoded.width);
  const size_t rows_with_points = static_cast<size_t>(
      std::count_if(rows.begin(), rows.end(), [](const auto& e) { return e.has_value(); }));
  if (measured && 2 * rows_with_points >= rows.size()) {
    say("beam elevations measured from the " + shape);
    return *measured;
  }
  if (const auto name = cloud::preset_with_beams(decoded.height)) {
    say("preset " + *name + " (" + shape + ", too few of them with points to measure)");
    return sensor_for(options, *name);
  }
  if (measured) {
    say("beam elevations measured from the " + std::to_string(rows_with_points) + " of " + shape +
        " with points");
    return *measured;
  }
  throw InputError(origin + ": an organized cloud of " + std::to_string(decoded.height) + " x " +
                   std::to_string(decoded.width) +
                   " whose sensor cannot be told; set --set sensor.preset=NAME (presets: " +
                   preset_list() + ")");
}

}  // namespace

config::SensorModel choose_sensor(const DecodedCloud& decoded, const SourceOptions& options,
                                  const std::string& origin, std::string* why,
                                  const std::string& unmatched_preset) {
  auto say = [why](const std::string& text) {
    if (why) *why = text;
  };
  const bool preset_given = options.sensor_preset != "auto";
  if (decoded.organized()) {
    config::SensorModel sensor;
    if (preset_given) {
      sensor = sensor_for(options, "");
      if (sensor.beams != decoded.height) {
        throw InputError(origin + ": an organized cloud of " + std::to_string(decoded.height) +
                         " rows, but sensor.preset " + options.sensor_preset + " has " +
                         std::to_string(sensor.beams) + " beams");
      }
      say("preset " + sensor.name + " (sensor.preset)");
    } else {
      sensor = sensor_of_rows(decoded, options, origin, say);
    }
    sensor.columns = decoded.width;
    return sensor;
  }
  if (preset_given) {
    say("preset " + options.sensor_preset + " (sensor.preset)");
    return sensor_for(options, "");
  }
  const PointCloud& cloud = decoded.cloud;
  if (!cloud.ring.empty()) {
    int highest = -1;
    for (size_t i = 0; i < cloud.size(); ++i) {
      if (is_return(cloud.xyz[i])) highest = std::max(highest, cloud.ring[i]);
    }
    if (const auto name = cloud::preset_for_rings(highest + 1)) {
      say("preset " + *name + " (rings up to " + std::to_string(highest) + ")");
      return sensor_for(options, *name);
    }
    throw InputError(origin + ": ring numbers up to " + std::to_string(highest) +
                     ", more than any preset has beams; set --set sensor.preset=NAME (presets: " +
                     preset_list() + ")");
  }
  if (const std::optional<cloud::SensorFromPoints> found = cloud::sensor_from_points(cloud)) {
    say(found->why);
    return found->preset ? sensor_for(options, *found->preset) : *found->measured;
  }
  if (!unmatched_preset.empty()) {
    say("preset " + unmatched_preset +
        " (the points match no preset's beams; the format's usual sensor)");
    return sensor_for(options, unmatched_preset);
  }
  throw InputError(origin +
                   ": an unorganized cloud without a ring field whose points match no preset's "
                   "beams; set --set sensor.preset=NAME (presets: " +
                   preset_list() + ")");
}

Scan cloud_to_scan(const DecodedCloud& decoded, const config::SensorModel& sensor,
                   const std::string& origin, OrganizeStats* stats,
                   std::vector<std::string>* warnings, const CloudTiming& timing,
                   std::string* times) {
  auto say = [times](std::string text) {
    if (times) *times = std::move(text);
  };
  const bool has_time_field = !decoded.cloud.time_offset_s.empty();
  const std::string field = has_time_field ? time_field_name(decoded) : std::string();
  AzimuthTimes derived;
  const bool derive = !has_time_field && timing.from_azimuth;
  if (derive) {
    derived = azimuth_times(decoded.cloud.xyz, sensor.rate_hz, timing.reference);
    if (!derived.found() && warnings) {
      warnings->push_back(origin + ": no per-point times from the azimuth: " + derived.problem);
    }
  }
  say(describe_times(field, derive ? &derived : nullptr));
  const std::vector<float>& point_times =
      derived.found() ? derived.offset_s : decoded.cloud.time_offset_s;

  Scan scan;
  if (decoded.organized()) {
    if (sensor.beams != decoded.height) {
      throw InputError(origin + ": an organized cloud of " + std::to_string(decoded.height) +
                       " rows for a sensor of " + std::to_string(sensor.beams) + " beams");
    }
    scan = organized_to_scan(decoded, point_times, origin, stats);
  } else if (derived.found()) {
    PointCloud timed = decoded.cloud;  // organize() takes the times from the cloud
    timed.time_offset_s = std::move(derived.offset_s);
    scan = organize(timed, sensor, stats);
  } else {
    scan = organize(decoded.cloud, sensor, stats);
  }
  scan.stamp_ns = decoded.stamp_ns.value_or(decoded.cloud.stamp_ns);
  if (has_time_field && check_times(scan, sensor.rate_hz, origin, warnings)) {
    say("none: the field '" + field + "' holds no times within a revolution");
  }
  return scan;
}

}  // namespace featsense::slam
