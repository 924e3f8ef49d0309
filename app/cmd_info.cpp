// featsense info: reads a whole recording once and reports what it holds.

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "featsense/bench/measurements.hpp"
#include "json_output.hpp"
#include "progress.hpp"
#include "source_options.hpp"

namespace featsense::app {

using bench::min_median_max;
namespace {

struct InfoOptions {
  InputOptions input;
  std::optional<std::string> json_path;
};

struct InfoResult {
  nlohmann::json json;
  std::string text;
};

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : " ") + w;
  return out;
}

InfoResult summarize(slam::ScanSource& source, bool quiet) {
  const slam::SourceInfo& info = source.info();
  Progress progress("frames", info.frames, quiet);
  std::vector<double> valid_points;
  int rows = 0;
  int cols = 0;
  bool same_shape = true;
  std::optional<int64_t> first_stamp;
  int64_t last_stamp = 0;
  while (std::optional<slam::Scan> scan = source.next()) {
    if (valid_points.empty()) {
      rows = scan->rows;
      cols = scan->cols;
    } else if (scan->rows != rows || scan->cols != cols) {
      same_shape = false;
    }
    valid_points.push_back(static_cast<double>(scan->valid_count()));
    if (!first_stamp) first_stamp = scan->stamp_ns;
    last_stamp = scan->stamp_ns;
    progress.update(valid_points.size());
  }
  progress.finish();
  const double seconds = progress.elapsed_s();
  const slam::ReadStats& stats = source.stats();
  const config::SensorModel& sensor = info.sensor;
  const double span_s = first_stamp ? 1e-9 * static_cast<double>(last_stamp - *first_stamp) : 0.0;
  const double fps = seconds > 0.0 ? static_cast<double>(valid_points.size()) / seconds : 0.0;
  const nlohmann::json valid = min_median_max(valid_points);

  InfoResult result;
  result.json = {{"input", info.path},
                 {"format", info.format},
                 {"detail", info.detail},
                 {"sensor",
                  {{"name", sensor.name},
                   {"from_metadata", info.sensor_from_metadata},
                   {"beams", sensor.beams},
                   {"columns", sensor.columns},
                   {"rate_hz", sensor.rate_hz},
                   {"vfov_deg", sensor.vertical_fov_rad() * 180.0 / M_PI}}},
                 {"frames", valid_points.size()},
                 {"skipped_frames", stats.frames_skipped},
                 {"warnings", stats.warning_count},
                 {"rows", same_shape ? rows : -1},
                 {"cols", same_shape ? cols : -1},
                 {"fields", info.fields},
                 {"topics", info.topics},
                 {"times", info.times},
                 {"imu", info.imu},
                 {"valid_points", valid},
                 {"time_span_s", span_s},
                 {"first_stamp_ns", first_stamp.value_or(0)},
                 {"last_stamp_ns", last_stamp},
                 {"read_seconds", seconds},
                 {"read_frames_per_s", fps}};

  char line[512];
  std::string& t = result.text;
  t += "input:     " + info.path + "\n";
  t += "format:    " + info.format + (info.detail.empty() ? "" : " (" + info.detail + ")") + "\n";
  std::snprintf(
      line, sizeof line, "sensor:    %s (%s): %d beams, %d columns, %.0f Hz, %.1f deg vertical\n",
      sensor.name.c_str(), info.sensor_from_metadata ? "from the recording" : "preset",
      sensor.beams, sensor.columns, sensor.rate_hz, sensor.vertical_fov_rad() * 180.0 / M_PI);
  t += line;
  std::snprintf(line, sizeof line, "frames:    %zu (%zu skipped, %zu warnings)\n",
                valid_points.size(), stats.frames_skipped, stats.warning_count);
  t += line;
  if (same_shape) {
    std::snprintf(line, sizeof line, "size:      %d x %d (rows x cols)\n", rows, cols);
  } else {
    std::snprintf(line, sizeof line, "size:      varies between frames\n");
  }
  t += line;
  t += "fields:    " + join(info.fields) + "\n";
  for (size_t i = 0; i < info.topics.size(); ++i) {
    t += (i == 0 ? "topics:    " : "           ") + info.topics[i] + "\n";
  }
  t += "times:     " + (info.times.empty() ? std::string("unknown") : info.times) + "\n";
  t += "imu:       " + (info.imu.empty() ? std::string("none") : info.imu) + "\n";
  std::snprintf(line, sizeof line, "valid points per frame: min %.0f, median %.0f, max %.0f\n",
                valid["min"].get<double>(), valid["median"].get<double>(),
                valid["max"].get<double>());
  t += line;
  std::snprintf(line, sizeof line, "time span: %.3f s\n", span_s);
  t += line;
  std::snprintf(line, sizeof line, "read in:   %.3f s (%.1f frames/s)\n", seconds, fps);
  t += line;
  for (const auto& warning : stats.warnings) t += "warning:   " + warning + "\n";
  if (stats.warning_count > stats.warnings.size()) {
    std::snprintf(line, sizeof line, "           ... and %zu more warnings\n",
                  stats.warning_count - stats.warnings.size());
    t += line;
  }
  return result;
}

}  // namespace

Command register_info(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand(
      "info", "What a recording holds: format, sensor, frames, size, fields, valid points");
  options->input.add_to(*command, /*input_optional=*/true);
  command->add_option("--json", options->json_path, "Also write the result as JSON ('-' = stdout)");
  return {command, [options, &context] {
            const config::Config config = context.load_config();
            if (options->input.input.empty()) {
              spdlog::info("no INPUT given: reading the built-in example (an analytic box room)");
            }
            std::unique_ptr<slam::ScanSource> source = options->input.open(config);
            const InfoResult result = summarize(*source, context.quiet);
            if (result.json["frames"].get<size_t>() == 0) {
              throw slam::InputError(source->info().path + ": no readable frame" +
                                     (source->stats().warnings.empty()
                                          ? std::string()
                                          : " (" + source->stats().warnings.front() + ")"));
            }
            if (options->json_path) write_json(result.json, *options->json_path);
            if (options->json_path != "-") std::cout << result.text;
          }};
}

}  // namespace featsense::app
