#include "map_report.hpp"

#include <map>

#include "featsense/bench/measurements.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::app {

using bench::peak_rss_mb;
using bench::timing_json;

nlohmann::json map_report_json(const config::Config& config, const slam::SourceInfo& input,
                               const mapping::MapResult& result) {
  const mapping::PassResult& run = result.mapped();
  nlohmann::json report;
  report["input"] = {{"path", input.path},
                     {"format", input.format},
                     {"sensor", input.sensor.name},
                     {"rows", input.sensor.beams},
                     {"cols", input.sensor.columns}};
  report["input"]["times"] = input.times;
  // Which sensor model, and why: the recording's metadata, a preset the points fit, a model
  // measured from them, or sensor.preset.
  report["input"]["sensor_from_metadata"] = input.sensor_from_metadata;
  report["input"]["detail"] = input.detail;
  report["frames"] = run.frames_mapped;
  report["frames_read"] = run.frames_read;
  report["frames_skipped"] = {{"without_pose", run.frames_without_pose},
                              {"outside_range", run.frames_outside_range}};
  report["interrupted"] = run.interrupted;
  // What the real-time policy of a live run gave up to keep the sensor's pace, by stage.
  report["real_time"] = {{"enabled", run.real_time.enabled},
                         {"scans_dropped",
                          {{"odometry_behind", run.real_time.scans_dropped_odometry_behind},
                           {"refinement_behind", run.real_time.scans_dropped_refinement_behind}}},
                         {"integrations_skipped", run.real_time.integrations_skipped},
                         {"refinement_clouds_skipped", run.real_time.refinement_clouds_skipped},
                         {"keyframes_skipped", run.real_time.keyframes_skipped}};
  report["backend"] = run.backend;
  report["backend_reason"] = run.backend_reason;
  report["poses"] = result.poses;
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
                       {"final_flush", timing_json(run.timings.final_flush_ms)},
                       {"preview", timing_json(run.timings.preview_ms)},
                       {"latency",
                        {{"pose", timing_json(run.timings.latency_pose_ms)},
                         {"final_pose", timing_json(run.timings.latency_final_pose_ms)},
                         {"integrated", timing_json(run.timings.latency_integrated_ms)}}}};
  report["wall_s"] = run.wall_s;
  report["scans_per_s"] = run.scans_per_s();
  report["recording_s"] = run.recording_s;
  // Above 1: faster than the sensor recorded.
  report["real_time_factor"] = run.wall_s > 0.0 ? run.recording_s / run.wall_s : 0.0;
  report["peak_rss_mb"] = peak_rss_mb();
  report["device_memory_mb"] = static_cast<double>(run.device_memory_bytes) / (1024.0 * 1024.0);
  report["map"] = {{"chunks", run.map_chunks},
                   {"continued_chunks", run.continued_chunks},
                   {"shifts", run.map.shifts},
                   {"bricks_spilled", run.map.bricks_spilled},
                   {"bricks_loaded", run.map.bricks_loaded},
                   {"chunks_written", run.map.chunks_written},
                   {"chunks_unchanged", run.map.chunks_unchanged},
                   {"syncs", run.map.syncs}};
  report["warnings"] = {{"count", run.warning_count}, {"first", run.warnings}};
  report["config"] = config::to_yaml(config);
  return report;
}

nlohmann::json sessions_json(const std::filesystem::path& path) {
  const storage::Hdf5ChunkStore store(path);
  std::map<uint32_t, size_t> keyframes;
  for (const storage::KeyframeKey& key : store.keyframe_keys()) ++keyframes[key.session];
  nlohmann::json out = nlohmann::json::array();
  for (const storage::MapSession& session : store.read_sessions()) {
    out.push_back({{"id", session.id},
                   {"input", session.input},
                   {"format", session.format},
                   {"scans", session.scans},
                   {"first_stamp_s", session.first_stamp_s},
                   {"last_stamp_s", session.last_stamp_s},
                   {"placement", session.placement},
                   {"keyframes", keyframes[session.id]}});
  }
  return out;
}

}  // namespace featsense::app
