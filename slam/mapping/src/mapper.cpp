#include "featsense/mapping/mapper.hpp"

#include <cstdio>
#include <stdexcept>
#include <utility>

#include "featsense/mapping/map_store.hpp"
#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/scan_motions.hpp"
#include "mapper_continuation.hpp"

namespace featsense::mapping {
namespace {

namespace fs = std::filesystem;

/// Why the loop closure does not run (empty: it does).
std::string loop_closure_off_because(bool odometry, const config::Config& config) {
  if (!odometry) return "the poses are given";
  if (!config.loop.enabled) return "loop.enabled is false";
  return "";
}

/// A file beside `map_path` for a map being made again: map.h5 -> map.<what>.h5.
fs::path beside(const fs::path& map_path, const std::string& what) {
  return fs::path(map_path).replace_extension("." + what + map_path.extension().string());
}

}  // namespace

Mapper::Mapper(MapperSettings settings, RunEvents events)
    : settings_(std::move(settings)), events_(std::move(events)) {
  const bool continuing_by_keyframes = settings_.continue_from && !settings_.given_poses;
  // A continued map keeps its voxel size and tau: decided here, once, before anything opens.
  if (continuing_by_keyframes) {
    continuation_ = std::make_unique<Continuation>(settings_, events_);
    settings_.config =
        with_map_geometry(std::move(settings_.config), continuation_->saved_metadata(),
                          *settings_.continue_from, events_);
  } else if (settings_.continue_from) {
    settings_.config =
        with_continued_geometry(std::move(settings_.config), *settings_.continue_from, events_);
  }
  const config::Config& config = settings_.config;
  if (settings_.given_poses) {
    given_ =
        slam::make_given_pose_locator(std::move(*settings_.given_poses), config.odometry.deskew);
    settings_.given_poses.reset();
    locator_ = given_.get();
  } else {
    // A recording continuing a map starts in its own frame until it is placed in the map.
    odometry_ = slam::odometry::make_odometry_locator(config, continuing_by_keyframes
                                                                  ? Eigen::Isometry3d::Identity()
                                                                  : settings_.T_map_first_scan);
    locator_ = odometry_.get();
  }
  pass_settings_ = pass_settings(config);
  pass_settings_.integrate = settings_.integrate;
  pass_settings_.real_time = settings_.real_time;
  if (odometry_ && config.refine.enabled) pass_settings_.refine = slam::refine::from_config(config);
  loops_off_because_ = loop_closure_off_because(odometry_ != nullptr, config);
  if (loops_off_because_.empty()) pass_settings_.loops = slam::loops::from_config(config);

  if (continuing_by_keyframes) {
    // Placed by its keyframes first: nothing is written until then.
    PassSettings first = pass_settings_;
    first.integrate = false;
    if (!first.loops) first.loops = continuation_->relocalize_settings().loop;
    first.relocalize = continuation_->stage();
    first_ = std::make_unique<MapPass>(*locator_, first, config, settings_.sensor,
                                       MapStoreRequest{}, events_);
    return;
  }
  // The preview watches the first pass: a live run has no other.
  PassSettings first = pass_settings_;
  first.preview = settings_.preview;
  first_ = std::make_unique<MapPass>(
      *locator_, first, config, settings_.sensor,
      MapStoreRequest{settings_.map_path, settings_.sensor.name, settings_.continue_from,
                      settings_.overwrite, settings_.session, nullptr},
      events_);
}

Mapper::~Mapper() = default;

MapPass& Mapper::first_pass() {
  if (finished_) throw std::logic_error("the Mapper was finished");
  return *first_;
}

const slam::Trajectory& Mapper::poses() const { return first_->result().poses; }
const PassResult& Mapper::diagnostics() const { return first_->result(); }
std::string Mapper::front_end() const { return locator_->description(); }
const std::optional<slam::refine::RefineSettings>& Mapper::refine_settings() const {
  return pass_settings_.refine;
}

void Mapper::integrate_final(std::vector<PlacedScan> scans) {
  for (PlacedScan& scan : scans) {
    if (stopped_) return;
    std::optional<LocatedScan> located = first_->make_rays(std::move(scan));
    if (!located) {
      stopped_ = true;
      return;
    }
    first_->integrate(std::move(*located));
  }
}

ScanUpdate Mapper::add_scan(slam::Scan scan) {
  if (finished_) throw std::logic_error("add_scan after the Mapper was finished");
  ScanUpdate update;
  if (stopped_) {
    update.stopped = true;
    update.why = "the run stopped taking scans";
    return update;
  }
  first_->count_read();
  std::optional<PlacedScan> placed = first_->locate(std::move(scan), &update.why);
  if (placed) {
    update.placed = true;
    update.placement = placed->placement;
    integrate_final(first_->refine(std::move(*placed)));
  }
  update.scans_mapped = first_->result().frames_mapped;
  update.stopped = stopped_;
  return update;
}

void Mapper::second_pass(MapResult& result) {
  const LoopOutcome& loops = *result.first.loops;
  events_.info(std::to_string(loops.loops.size()) + " loops closed" +
               (loops.gravity.observations > 0 ? ", levelled by gravity" : "") +
               (loops.final_optimisation.gyro_edges > 0 ? ", turns held by the gyroscope" : "") +
               ": mapping the recording again with the corrected poses");
  const config::Config& config = settings_.config;
  const fs::path replay_path = beside(settings_.map_path, "corrected");
  try {
    build_then_replace(replay_path, settings_.map_path, [&] {
      const std::unique_ptr<slam::ScanSource> again = settings_.reopen();
      // Each scan deskewed as the first pass placed it (scan_motions.hpp), from its corrected
      // pose.
      const std::unique_ptr<slam::ScanLocator> corrected =
          config.odometry.deskew
              ? slam::make_replay_locator(loops.corrected, result.first.scan_motions)
              : slam::make_given_pose_locator(loops.corrected, false);
      PassSettings replay = pass_settings_;
      replay.refine.reset();
      replay.loops.reset();
      SessionDescription session = settings_.session;
      session.placement += ", loops closed";
      PipelineSettings pipeline;
      pipeline.range = settings_.range;
      result.second = run_pass(
          *again, *corrected, replay, config,
          {replay_path, settings_.sensor.name, std::nullopt, true, session, &loops.keyframes},
          events_, pipeline);
      if (result.second->interrupted) throw Interrupted("interrupted");
    });
    result.second_pass = {SecondPass::kMappedAgain, "mapped again with the corrected poses"};
  } catch (const Interrupted&) {
    result.second.reset();
    result.first.interrupted = true;
    result.second_pass = {SecondPass::kInterrupted,
                          "interrupted: the map keeps the odometry's poses"};
  } catch (const std::exception& e) {
    // The input changed or went away since the first pass: its map stays.
    result.second.reset();
    events_.warn(std::string("the second pass failed: ") + e.what() +
                 "; the map keeps the odometry's poses");
    result.second_pass = {SecondPass::kFailed, std::string("failed (") + e.what() +
                                                   "): the map keeps the odometry's poses"};
  }
}

MapResult Mapper::finish() {
  if (finished_) throw std::logic_error("a Mapper was finished twice");
  finished_ = true;
  // Scans given one at a time: the last stretch's poses become final here (after the
  // pipeline, nothing is left).
  integrate_final(first_->finish_refinement());
  MapResult result;
  result.first = first_->close();
  result.refine = pass_settings_.refine;
  result.loops_off_because = loops_off_because_;
  if (odometry_) result.odometry = odometry_->counts();
  if (continuation_) {
    continuation_->finish(*this, result);
  } else {
    const LoopOutcome* loops = result.first.loops ? &*result.first.loops : nullptr;
    result.second_pass =
        plan_second_pass(loops, result.first.interrupted, settings_.integrate,
                         static_cast<bool>(settings_.reopen), settings_.config.map.voxel_size_m);
    if (result.second_pass.kind == SecondPass::kMapAgain) second_pass(result);
    // With loops closed and no second pass, the corrected poses all the same (to map later
    // with them as given poses).
    result.final_poses = loops && loops->corrects_poses() && !result.second ? loops->corrected
                                                                            : result.mapped().poses;
  }
  result.config = settings_.config;
  result.poses = locator_->description() + (pass_settings_.refine ? ", refined (VGICP)" : "") +
                 (result.second ? ", loops closed" : "");
  return result;
}

MapResult map_source(slam::ScanSource& source, Mapper& mapper) {
  PipelineSettings pipeline;
  pipeline.range = mapper.settings().range;
  drive_pass(source, mapper.first_pass(), pipeline);
  return mapper.finish();
}

}  // namespace featsense::mapping
