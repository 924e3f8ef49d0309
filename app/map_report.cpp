#include "map_report.hpp"

#include <sys/resource.h>

#include "timing_stats.hpp"

namespace featsense::app {
double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

nlohmann::json map_report_json(const MapRunSummary& summary) {
  const PipelineResult& run = *summary.pipeline;
  nlohmann::json report;
  report["input"] = {{"path", summary.input->path},
                     {"format", summary.input->format},
                     {"sensor", summary.input->sensor.name},
                     {"rows", summary.input->sensor.beams},
                     {"cols", summary.input->sensor.columns}};
  report["input"]["times"] = summary.input->times;
  report["frames"] = run.frames_mapped;
  report["frames_read"] = run.frames_read;
  report["frames_skipped"] = {{"without_pose", run.frames_without_pose},
                              {"outside_range", run.frames_outside_range}};
  report["interrupted"] = run.interrupted;
  report["backend"] = summary.backend;
  report["backend_reason"] = summary.backend_reason;
  report["poses"] = summary.poses;
  report["points"] = run.points;
  report["mixed_pixels_dropped"] = run.mixed_pixels_dropped;
  report["voxels_updated"] = run.voxels_updated;
  report["timings"] = {{"read", timing_json(run.timings.read_ms)},
                       {"locate", timing_json(run.timings.locate_ms)},
                       {"refine", timing_json(run.timings.refine_ms)},
                       {"rays", timing_json(run.timings.rays_ms)},
                       {"shift", timing_json(run.timings.shift_ms)},
                       {"integrate", timing_json(run.timings.integrate_ms)},
                       {"flush", timing_json(run.timings.flush_ms)},
                       {"final_flush", timing_json(summary.final_flush_ms)}};
  report["wall_s"] = run.wall_s;
  report["scans_per_s"] =
      run.wall_s > 0.0 ? static_cast<double>(run.frames_mapped) / run.wall_s : 0.0;
  report["recording_s"] = run.recording_s;
  // Above 1: faster than the sensor recorded.
  report["real_time_factor"] = run.wall_s > 0.0 ? run.recording_s / run.wall_s : 0.0;
  report["peak_rss_mb"] = peak_rss_mb();
  report["device_memory_mb"] = static_cast<double>(summary.device_memory_bytes) / (1024.0 * 1024.0);
  report["map"] = {{"chunks", summary.map_chunks},
                   {"continued_chunks", summary.continued_chunks},
                   {"shifts", summary.map.shifts},
                   {"bricks_spilled", summary.map.bricks_spilled},
                   {"bricks_loaded", summary.map.bricks_loaded},
                   {"chunks_written", summary.map.chunks_written},
                   {"chunks_unchanged", summary.map.chunks_unchanged},
                   {"syncs", summary.map.syncs}};
  report["warnings"] = {{"count", run.warning_count}, {"first", run.warnings}};
  report["config"] = config::to_yaml(*summary.config);
  return report;
}

}  // namespace featsense::app
