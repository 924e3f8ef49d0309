#include "featsense/mapping/loop_stage.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "background_thread.hpp"
#include "featsense/slam/refine/refinement_cloud.hpp"

namespace featsense::mapping {
namespace {

/// Keyframes waiting for the loop thread: enough to ride out one verification that takes
/// long, few enough that the map is not held up for long.
constexpr size_t kKeyframesQueued = 8;

}  // namespace

slam::Trajectory corrected_path(const slam::loops::TrajectoryCorrection& correction,
                                const slam::Trajectory& path,
                                const std::vector<double>& travelled_m) {
  slam::Trajectory out;
  for (size_t i = 0; i < path.size(); ++i)
    out.push_back(path.stamps_ns[i], correction.apply(travelled_m[i], path.poses[i]));
  return out;
}

LoopStage::LoopStage(const slam::loops::LoopSettings& settings,
                     std::optional<RelocalizeStage> relocalize, bool never_wait)
    : settings_(settings),
      selector_(settings.keyframe_distance_m, settings.keyframe_angle_deg),
      closer_(settings),
      queue_(kKeyframesQueued),
      never_wait_(never_wait),
      relocalize_(relocalize),
      worker_([this] { work(); }) {}

LoopStage::~LoopStage() {
  abandon();
  if (worker_.joinable()) worker_.join();
}

void LoopStage::work() {
  if (never_wait_) {
    // Real time: below the odometry (background_thread.hpp), like the other lagging stages.
    BackgroundThread(kBackgroundNice).run([this] { take_keyframes(); });
  } else {
    take_keyframes();
  }
}

void LoopStage::take_keyframes() {
  try {
    while (std::optional<KeyframeJob> job = queue_.pop()) {
      closer_.add_keyframe(job->stamp_ns, job->travelled_m, job->T_map_sensor, job->points);
      if (!relocalize_ || relocalize_->relocalizer->placement()) continue;
      if (job->scan >= relocalize_->max_scans) {
        relocalize_gave_up_.store(true);
        continue;
      }
      relocalize_->relocalizer->add_keyframe(job->stamp_ns, job->T_map_sensor, job->travelled_m,
                                             job->points);
    }
  } catch (...) {
    failure_ = std::current_exception();
    queue_.abandon();
  }
}

bool LoopStage::offer(const slam::Scan& scan, const slam::ScanPlacement& placement) {
  if (relocalize_gave_up_.load()) return false;
  const size_t scan_index = path_.size();
  const bool keyframe = selector_.next(placement.T_map_sensor);
  path_.push_back(placement.stamp_ns, placement.T_map_sensor);
  travelled_m_.push_back(selector_.travelled_m());
  slam::loops::append_in_time_order(&imu_, scan.imu);
  if (!keyframe) return true;
  // Only this thread pushes: a queue found not full takes the job without waiting.
  if (never_wait_ && queue_.full()) {
    ++keyframes_skipped_;
    return true;
  }
  KeyframeJob job;
  job.stamp_ns = placement.stamp_ns;
  job.travelled_m = selector_.travelled_m();
  job.T_map_sensor = placement.T_map_sensor;
  job.scan = scan_index;
  const auto cloud_start = std::chrono::steady_clock::now();
  job.points = slam::refine::voxel_centroids(scan, placement, settings_.cloud_voxel_m);
  const auto start = std::chrono::steady_clock::now();
  cloud_ms_.push_back(std::chrono::duration<double, std::milli>(start - cloud_start).count());
  const bool queued = queue_.push(std::move(job));
  wait_ms_ +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return queued;
}

void LoopStage::abandon() { queue_.abandon(); }

LoopOutcome LoopStage::finish() {
  queue_.close();
  if (worker_.joinable()) worker_.join();
  if (failure_) std::rethrow_exception(failure_);
  finished_ = true;
  LoopOutcome out;
  out.keyframe_cloud_ms = cloud_ms_;
  // The loop thread is done with the closer: the gravity goes in from here.
  out.final_optimisation = closer_.finish(path_.stamps_ns, path_.poses, imu_);
  out.gravity = out.final_optimisation.gravity;
  out.loops = closer_.loops();
  out.counts = closer_.counts();
  out.keyframes = closer_.release_keyframe_records();  // one copy of the clouds, not two
  out.keyframe_queue_wait_ms = wait_ms_;
  if (relocalize_) {
    out.relocalization = relocalize_->relocalizer->placement();
    out.relocalize_counts = relocalize_->relocalizer->counts();
    out.relocalize_gave_up = relocalize_gave_up_.load();
  }
  out.before = path_;
  out.corrected = corrected();
  for (size_t i = 0; i < path_.size(); ++i) {
    out.corrections_max_m =
        std::max(out.corrections_max_m,
                 (out.corrected.poses[i].translation() - path_.poses[i].translation()).norm());
  }
  return out;
}

slam::loops::LoopCloser& LoopStage::closer_after_finish() {
  if (!finished_) throw std::logic_error("the loop closer belongs to its thread until finish()");
  return closer_;
}

slam::Trajectory LoopStage::corrected() const {
  return corrected_path(closer_.correction(), path_, travelled_m_);
}

}  // namespace featsense::mapping
