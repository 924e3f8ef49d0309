#include "featsense/mapping/map_pass.hpp"

#include "preview_mesher.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "featsense/mapping/map_store.hpp"
#include "featsense/mapping/scan_to_rays.hpp"
#include "featsense/slam/preprocess/mixed_pixel_filter.hpp"
#include "featsense/tsdf/integrator.hpp"

namespace featsense::mapping {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

/// The map a pass writes: the store, the TSDF backend (made when the first scan arrives) and
/// the local map that moves with the sensor and spills into the store.
struct MapPass::Store {
  MapStore files;
  tsdf::TsdfSettings tsdf;
  std::unique_ptr<tsdf::Integrator> integrator;
  std::unique_ptr<storage::ShiftingMap> map;
  bool closed = false;
};

PassSettings pass_settings(const config::Config& config) {
  PassSettings settings;
  settings.flush_interval_s = config.map.flush_interval_s;
  settings.drop_mixed_pixels = config.sensor.drop_mixed_pixels;
  return settings;
}

MapPass::MapPass(slam::ScanLocator& locator, const PassSettings& settings,
                 const config::Config& config, const config::SensorModel& sensor,
                 const MapStoreRequest& store, RunEvents events)
    : locator_(locator),
      settings_(settings),
      config_(config),
      sensor_(sensor),
      request_(store),
      events_(std::move(events)),
      started_(Clock::now()),
      last_flush_(started_) {
  if (settings_.integrate) {
    store_ = std::make_unique<Store>();
    store_->files = open_map_store(request_.path, config_, request_.sensor_name,
                                   request_.continue_from, request_.overwrite);
    result_.continued_chunks = store_->files.continued_chunks;
    store_->tsdf = tsdf::TsdfSettings::from_config(config_.map, sensor_);
  }
  if (settings_.refine) {
    refiner_ = std::make_unique<slam::refine::PlacementRefiner>(*settings_.refine);
    result_.unrefined_poses.emplace();
  }
  if (settings_.loops)
    loops_ =
        std::make_unique<LoopStage>(*settings_.loops, settings_.relocalize, settings_.real_time);
  if (settings_.preview) {
    preview_ = std::make_unique<PreviewMesher>(*settings_.preview, config_.map.voxel_size_m,
                                               config_.map.truncation_m);
  }
}

MapPass::~MapPass() {
  if (!closed_) abandon();
}

void MapPass::warn(const std::string& message) {
  std::lock_guard<std::mutex> lock(warnings_mutex_);
  ++result_.warning_count;
  if (result_.warnings.size() < slam::ReadStats::kMaxKeptWarnings) {
    result_.warnings.push_back(message);
    events_.warn(message);
  }
}

std::optional<PlacedScan> MapPass::locate(slam::Scan scan, std::string* why_out) {
  const Clock::time_point start = Clock::now();
  latency_.ready(scan.sequence);  // kept where the reader marked it already
  if (settings_.drop_mixed_pixels) result_.mixed_pixels_dropped += slam::drop_mixed_pixels(scan);
  std::string why;
  std::optional<slam::ScanPlacement> placement = locator_.locate(scan, why);
  if (!placement) {
    latency_.since_ready(scan.sequence, true);
    ++result_.frames_without_pose;
    warn("skipped: " + why);
    if (why_out) *why_out = why;
    return std::nullopt;
  }
  // A placement that comes with a reason is a pose the front end could not trust (e.g. the
  // odometry's prediction): counted and kept.
  if (!why.empty()) warn(why);
  if (why_out) *why_out = why;
  result_.timings.locate_ms.push_back(ms_since(start));
  const std::optional<double> latency_ms = latency_.since_ready(scan.sequence);
  if (latency_ms) result_.timings.latency_pose_ms.push_back(*latency_ms);
  if (preview_) {
    std::lock_guard<std::mutex> lock(latest_mutex_);
    latest_ = {placement->T_map_sensor, placement->stamp_ns, true,
               latency_ms ? *latency_ms : std::nan("")};
  }
  return PlacedScan{std::move(scan), std::move(*placement)};
}

std::vector<PlacedScan> MapPass::release(std::vector<slam::ScanPlacement> final) {
  std::vector<PlacedScan> out;
  for (slam::ScanPlacement& placement : final) {
    if (held_.empty() || held_.front().placement.sequence != placement.sequence) {
      throw std::logic_error("refinement: a final pose out of order");
    }
    out.push_back(std::move(held_.front()));
    held_.pop_front();
    out.back().placement = std::move(placement);
  }
  return out;
}

std::vector<PlacedScan> MapPass::refine(PlacedScan placed, bool behind) {
  if (!refiner_) {
    std::vector<PlacedScan> out;
    out.push_back(std::move(placed));
    return out;
  }
  const Clock::time_point start = Clock::now();
  result_.unrefined_poses->push_back(placed.placement.stamp_ns, placed.placement.T_map_sensor);
  std::vector<slam::ScanPlacement> final = refiner_->add(placed.scan, placed.placement, behind);
  held_.push_back(std::move(placed));
  result_.refine_most_held = std::max(result_.refine_most_held, held_.size());
  std::vector<PlacedScan> out = release(std::move(final));
  result_.timings.refine_ms.push_back(ms_since(start));
  return out;
}

std::vector<PlacedScan> MapPass::finish_refinement() {
  if (!refiner_ || refinement_finished_) return {};
  refinement_finished_ = true;
  std::vector<PlacedScan> out = release(refiner_->finish());
  result_.refine = refiner_->counts();
  result_.refine_cloud_ms = refiner_->cloud_ms();
  return out;
}

void MapPass::count_dropped(uint64_t sequence, ScanDrop why) {
  latency_.since_ready(sequence, true);  // forgotten: no stage will see it
  (why == ScanDrop::kOdometryBehind ? dropped_odometry_behind_ : dropped_refinement_behind_)
      .fetch_add(1);
}

std::optional<LocatedScan> MapPass::make_rays(PlacedScan placed, bool skip_integration) {
  const Clock::time_point start = Clock::now();
  const bool integrates =
      settings_.integrate && !skip_integration &&
      (!settings_.reintegrate || settings_.reintegrate->origin_at(placed.placement.stamp_ns));
  if (const std::optional<double> ms =
          latency_.since_ready(placed.placement.sequence, !integrates)) {
    result_.timings.latency_final_pose_ms.push_back(*ms);
  }
  if (loops_ && !loops_->offer(placed.scan, placed.placement)) return std::nullopt;
  if (loops_) result_.scan_motions.add(placed.scan, placed.placement);
  LocatedScan located;
  located.integrate = integrates;
  if (integrates) located.rays = scan_to_rays(placed.scan, placed.placement);
  located.placement = std::move(placed.placement);
  result_.timings.rays_ms.push_back(ms_since(start));
  return located;
}

void MapPass::open_map(const LocatedScan& first) {
  store_->integrator = tsdf::make_integrator(config_.map.backend, store_->tsdf,
                                             local_map_anchor(first.placement.T_map_sensor),
                                             &result_.backend_reason);
  events_.info("TSDF: " + result_.backend_reason);
  store_->map = std::make_unique<storage::ShiftingMap>(*store_->integrator, *store_->files.store,
                                                       config_.map.shift_threshold_m);
}

void MapPass::integrate(LocatedScan scan) {
  if (preview_) preview_->add_pose(scan.placement.stamp_ns, scan.placement.T_map_sensor);
  if (settings_.integrate && !scan.integrate) {  // skipped to keep up, or kept: the pose only
    result_.poses.push_back(scan.placement.stamp_ns, scan.placement.T_map_sensor);
    ++(settings_.reintegrate ? result_.frames_not_reintegrated
                             : result_.real_time.integrations_skipped);
    update_preview(false);
    return;
  }
  if (!settings_.integrate) {
    result_.poses.push_back(scan.placement.stamp_ns, scan.placement.T_map_sensor);
    ++result_.frames_mapped;
    report_progress();
    update_preview(false);
    return;
  }
  if (!store_->map) open_map(scan);
  storage::ShiftingMap& map = *store_->map;
  Clock::time_point start = Clock::now();
  if (settings_.reintegrate) {
    map.move_to(*settings_.reintegrate->origin_at(scan.placement.stamp_ns));
  } else {
    map.follow(local_map_anchor(scan.placement.T_map_sensor));
  }
  result_.timings.shift_ms.push_back(ms_since(start));

  start = Clock::now();
  const tsdf::IntegrationStats stats = map.integrator().integrate(scan.rays);
  result_.timings.integrate_ms.push_back(ms_since(start));
  result_.points += scan.rays.size();
  result_.voxels_updated += stats.voxels_updated;
  if (const std::optional<double> ms = latency_.since_ready(scan.placement.sequence, true)) {
    result_.timings.latency_integrated_ms.push_back(*ms);
    integration_latency_ms_ = *ms;
  }
  result_.poses.push_back(scan.placement.stamp_ns, scan.placement.T_map_sensor);
  ++result_.frames_mapped;

  if (std::chrono::duration<double>(Clock::now() - last_flush_).count() >=
      settings_.flush_interval_s) {
    start = Clock::now();
    map.sync();
    result_.timings.flush_ms.push_back(ms_since(start));
    last_flush_ = Clock::now();
  }
  if (preview_) preview_->mark(scan.rays, map.integrator().geometry());
  report_progress();
  update_preview(false);
}

void MapPass::update_preview(bool last) {
  if (!preview_ || (!last && !preview_->due())) return;
  const Clock::time_point start = Clock::now();
  MapPreview status;
  {
    std::lock_guard<std::mutex> lock(latest_mutex_);
    status.latest_pose = latest_.pose;
    status.latest_stamp_ns = latest_.stamp_ns;
    status.has_latest_pose = latest_.known;
    status.pose_latency_ms = latest_.latency_ms;
  }
  status.integration_latency_ms = integration_latency_ms_;
  status.frames_read = frames_read_.load();
  status.frames_mapped = result_.frames_mapped;
  status.integrations_skipped = result_.real_time.integrations_skipped;
  storage::ShiftingMap* map = store_ ? store_->map.get() : nullptr;
  Eigen::Vector3d sensor = Eigen::Vector3d::Zero();
  if (!result_.poses.empty()) sensor = result_.poses.poses.back().translation();
  if (last) {
    preview_->finish(map, sensor, std::move(status));
  } else {
    preview_->refresh(map, sensor, std::move(status));
  }
  result_.timings.preview_ms.push_back(ms_since(start));
}

void MapPass::report_progress() {
  if (!events_.progress) return;
  RunProgress progress;
  progress.frames_read = frames_read_.load();
  progress.frames_mapped = result_.frames_mapped;
  progress.total_frames = total_frames_;
  progress.integrating = settings_.integrate;
  if (store_ && store_->map) {
    const storage::ShiftingMapStats& stats = store_->map->stats();
    progress.shifts = stats.shifts;
    progress.chunks_written = stats.chunks_written;
  }
  events_.progress(progress);
}

void MapPass::add_source_warnings(const slam::ReadStats& read) {
  std::lock_guard<std::mutex> lock(warnings_mutex_);
  for (const std::string& warning : read.warnings) {
    if (result_.warnings.size() < slam::ReadStats::kMaxKeptWarnings)
      result_.warnings.push_back(warning);
  }
  result_.warning_count += read.warning_count;
}

void MapPass::abandon() {
  closed_ = true;
  preview_.reset();
  if (loops_) loops_->abandon();
  if (!store_ || store_->closed) return;
  store_->closed = true;
  // Whatever was integrated goes to disk before the error is reported.
  try {
    if (store_->map) store_->map->sync();
    store_->files.store->close();
  } catch (const std::exception& e) {
    events_.warn(std::string("could not write the map after the failure: ") + e.what());
  }
}

void MapPass::write_store() {
  storage::Hdf5ChunkStore& store = *store_->files.store;
  if (store_->map) {
    const Clock::time_point start = Clock::now();
    store_->map->sync();
    result_.timings.final_flush_ms.push_back(ms_since(start));
    result_.map = store_->map->stats();
  }
  slam::Trajectory all_poses = store_->files.earlier_poses;
  for (size_t i = 0; i < result_.poses.size(); ++i)
    all_poses.push_back(result_.poses.stamps_ns[i], result_.poses.poses[i]);
  store.write_trajectory(to_store_poses(all_poses));
  const std::vector<slam::loops::KeyframeRecord> no_keyframes;
  const std::vector<slam::loops::KeyframeRecord>& keyframes =
      request_.keyframes ? *request_.keyframes
                         : (result_.loops ? result_.loops->keyframes : no_keyframes);
  record_session(store, request_.session, result_.poses, keyframes);
  result_.map_chunks = store.keys().size();
  store.close();
  store_->closed = true;
  if (store_->integrator) {
    result_.backend = store_->integrator->backend_name();
    if (result_.backend == "cuda") result_.device_memory_bytes = store_->integrator->memory_bytes();
  }
}

PassResult MapPass::close() {
  if (closed_) throw std::logic_error("a map pass was closed twice");
  try {
    if (loops_) {
      // On a stop too: the keyframes queued are few, and the corrected path is worth having.
      const Clock::time_point start = Clock::now();
      result_.loops = loops_->finish();
      result_.timings.loops_finish_ms = ms_since(start);
    }
    result_.frames_read = frames_read_.load();
    result_.real_time.enabled = settings_.real_time;
    result_.real_time.scans_dropped_odometry_behind = dropped_odometry_behind_.load();
    result_.real_time.scans_dropped_refinement_behind = dropped_refinement_behind_.load();
    if (loops_) result_.real_time.keyframes_skipped = loops_->keyframes_skipped();
    if (refiner_) result_.real_time.refinement_clouds_skipped = refiner_->clouds_skipped();
    result_.wall_s = std::chrono::duration<double>(Clock::now() - started_).count();
    result_.interrupted = events_.stop.stop_requested();
    if (!result_.poses.empty()) {
      result_.recording_s =
          static_cast<double>(result_.poses.stamps_ns.back() - result_.poses.stamps_ns.front()) *
          1e-9;
    }
    // The last refresh before the store closes (it reads the chunks the local map left).
    update_preview(true);
    preview_.reset();
    if (store_) write_store();
  } catch (...) {
    abandon();
    throw;
  }
  closed_ = true;
  // The local map, its integrator, the refinement's and the loops' clouds are of no more use:
  // a second pass runs while this one's result is kept, and must not hold them twice.
  store_.reset();
  refiner_.reset();
  loops_.reset();
  return std::move(result_);
}

}  // namespace featsense::mapping
