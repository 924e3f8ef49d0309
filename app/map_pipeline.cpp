#include "map_pipeline.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "bounded_queue.hpp"
#include "featsense/slam/preprocess/mixed_pixel_filter.hpp"
#include "progress.hpp"
#include "scan_to_rays.hpp"
#include "stop_signal.hpp"

namespace featsense::app {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// What the three stages share: the first error, the warnings, the stop flag.
class PipelineState {
 public:
  bool stopping() const { return failed_.load() || StopSignal::requested(); }

  void fail(std::exception_ptr error) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = error;
    failed_.store(true);
  }
  void rethrow_failure() const {
    if (error_) std::rethrow_exception(error_);
  }

  void warn(const std::string& message, PipelineResult& result) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++result.warning_count;
    if (result.warnings.size() < slam::ReadStats::kMaxKeptWarnings) {
      result.warnings.push_back(message);
      spdlog::warn("{}", message);
    }
  }

 private:
  std::mutex mutex_;
  std::atomic<bool> failed_{false};
  std::exception_ptr error_;
};

bool before_range(const slam::Scan& scan, const FrameRange& range, int64_t first_stamp_ns) {
  if (range.first_frame && scan.sequence < *range.first_frame) return true;
  if (range.first_stamp_ns && scan.stamp_ns < *range.first_stamp_ns) return true;
  return range.first_s &&
         static_cast<double>(scan.stamp_ns - first_stamp_ns) * 1e-9 < *range.first_s;
}

bool after_range(const slam::Scan& scan, const FrameRange& range, int64_t first_stamp_ns) {
  if (range.last_frame && scan.sequence > *range.last_frame) return true;
  if (range.last_stamp_ns && scan.stamp_ns > *range.last_stamp_ns) return true;
  return range.last_s && static_cast<double>(scan.stamp_ns - first_stamp_ns) * 1e-9 > *range.last_s;
}

void read_scans(slam::ScanSource& source, const FrameRange& range, BoundedQueue<slam::Scan>& out,
                PipelineState& state, PipelineResult& result) {
  std::optional<int64_t> first_stamp_ns;
  while (!state.stopping()) {
    const Clock::time_point start = Clock::now();
    std::optional<slam::Scan> scan = source.next();
    if (!scan) break;
    ++result.frames_read;
    if (!first_stamp_ns) first_stamp_ns = scan->stamp_ns;
    if (after_range(*scan, range, *first_stamp_ns)) break;
    if (before_range(*scan, range, *first_stamp_ns)) {
      ++result.frames_outside_range;
      continue;
    }
    result.timings.read_ms.push_back(ms_since(start));
    if (!out.push(std::move(*scan))) break;
  }
}

/// A scan with its place, on its way to becoming rays.
struct PlacedScan {
  slam::Scan scan;
  slam::ScanPlacement placement;
};

void locate_scans(slam::ScanLocator& locator, bool drop_mixed, BoundedQueue<slam::Scan>& in,
                  BoundedQueue<PlacedScan>& out, PipelineState& state, PipelineResult& result) {
  while (std::optional<slam::Scan> scan = in.pop()) {
    const Clock::time_point start = Clock::now();
    if (drop_mixed) result.mixed_pixels_dropped += slam::drop_mixed_pixels(*scan);
    std::string why;
    std::optional<slam::ScanPlacement> placement = locator.locate(*scan, why);
    if (!placement) {
      ++result.frames_without_pose;
      state.warn("skipped: " + why, result);
      continue;
    }
    // A placement that comes with a reason is a pose the front end could not trust (e.g.
    // the odometry's prediction): counted and kept.
    if (!why.empty()) state.warn(why, result);
    result.timings.locate_ms.push_back(ms_since(start));
    if (!out.push(PlacedScan{std::move(*scan), std::move(*placement)})) break;
  }
}

/// Sends on the placed scans whose poses became final: `held` is in the refiner's order.
bool send_final(std::vector<slam::ScanPlacement> final, std::deque<PlacedScan>& held,
                BoundedQueue<PlacedScan>& out) {
  for (slam::ScanPlacement& placement : final) {
    if (held.empty() || held.front().placement.sequence != placement.sequence) {
      throw std::logic_error("refinement: a final pose out of order");
    }
    PlacedScan scan = std::move(held.front());
    held.pop_front();
    scan.placement = std::move(placement);
    if (!out.push(std::move(scan))) return false;
  }
  return true;
}

/// The refinement holds each stretch's scans until their poses are final; the queue before
/// it is deep enough that the odometry does not wait while a stretch is registered.
void refine_scans(const slam::refine::RefineSettings& settings, BoundedQueue<PlacedScan>& in,
                  BoundedQueue<PlacedScan>& out, PipelineResult& result) {
  slam::refine::PlacementRefiner refiner(settings);
  std::deque<PlacedScan> held;
  result.unrefined_poses.emplace();
  while (std::optional<PlacedScan> placed = in.pop()) {
    const Clock::time_point start = Clock::now();
    result.unrefined_poses->push_back(placed->placement.stamp_ns, placed->placement.T_map_sensor);
    std::vector<slam::ScanPlacement> final = refiner.add(placed->scan, placed->placement);
    held.push_back(std::move(*placed));
    result.refine_most_held = std::max(result.refine_most_held, held.size());
    result.timings.refine_ms.push_back(ms_since(start));
    if (!send_final(std::move(final), held, out)) break;
  }
  // The end of the input, or a stop: the last stretch is refined and mapped too.
  send_final(refiner.finish(), held, out);
  result.refine = refiner.counts();
  result.refine_cloud_ms = refiner.cloud_ms();
}

/// Rays in a stage of their own: with odometry the front end is the pipeline's slowest
/// stage, and the deskewing of every point need not wait for it. The poses are final here:
/// the loop closure sees each scan too. Without integration there are no rays to make.
void make_rays(BoundedQueue<PlacedScan>& in, BoundedQueue<LocatedScan>& out, LoopStage* loops,
               bool integrate, PipelineResult& result) {
  while (std::optional<PlacedScan> placed = in.pop()) {
    const Clock::time_point start = Clock::now();
    if (loops && !loops->offer(placed->scan, placed->placement)) break;
    if (loops) result.scan_motions.add(placed->scan, placed->placement);
    LocatedScan located;
    if (integrate) located.rays = scan_to_rays(placed->scan, placed->placement);
    located.placement = std::move(placed->placement);
    result.timings.rays_ms.push_back(ms_since(start));
    if (!out.push(std::move(located))) break;
  }
}

class MappingStage {
 public:
  MappingStage(const MapOpener& open_map, const PipelineSettings& settings, PipelineResult& result)
      : open_map_(open_map), settings_(settings), result_(result) {}

  void run(BoundedQueue<LocatedScan>& in) {
    Progress progress("frames", settings_.total_frames, settings_.quiet);
    Clock::time_point last_flush = Clock::now();
    while (std::optional<LocatedScan> scan = in.pop()) {
      if (!settings_.integrate) {
        result_.poses.push_back(scan->placement.stamp_ns, scan->placement.T_map_sensor);
        ++result_.frames_mapped;
        progress.update(result_.frames_read, std::to_string(result_.frames_mapped) + " placed");
        continue;
      }
      if (!map_) map_ = &open_map_(*scan);
      const Eigen::Vector3d at = scan->placement.T_map_sensor.translation();
      Clock::time_point start = Clock::now();
      map_->follow(
          {static_cast<float>(at.x()), static_cast<float>(at.y()), static_cast<float>(at.z())});
      result_.timings.shift_ms.push_back(ms_since(start));

      start = Clock::now();
      const tsdf::IntegrationStats stats = map_->integrator().integrate(scan->rays);
      result_.timings.integrate_ms.push_back(ms_since(start));
      result_.points += scan->rays.size();
      result_.voxels_updated += stats.voxels_updated;
      result_.poses.push_back(scan->placement.stamp_ns, scan->placement.T_map_sensor);
      ++result_.frames_mapped;

      if (std::chrono::duration<double>(Clock::now() - last_flush).count() >=
          settings_.flush_interval_s) {
        start = Clock::now();
        map_->sync();
        result_.timings.flush_ms.push_back(ms_since(start));
        last_flush = Clock::now();
      }
      progress.update(result_.frames_read, status());
    }
  }

 private:
  std::string status() const {
    const storage::ShiftingMapStats& stats = map_->stats();
    char text[96];
    std::snprintf(text, sizeof(text), "%zu mapped, %zu shifts, %zu chunks written",
                  result_.frames_mapped, stats.shifts, stats.chunks_written);
    return text;
  }

  const MapOpener& open_map_;
  const PipelineSettings& settings_;
  PipelineResult& result_;
  storage::ShiftingMap* map_ = nullptr;
};

/// Runs `work` and turns an exception into a pipeline failure that stops every stage.
template <typename Work>
void guarded(PipelineState& state, const Work& work) {
  try {
    work();
  } catch (...) {
    state.fail(std::current_exception());
  }
}

}  // namespace

PipelineResult run_map_pipeline(slam::ScanSource& source, slam::ScanLocator& locator,
                                const MapOpener& open_map, const PipelineSettings& settings) {
  PipelineResult result;
  PipelineState state;
  BoundedQueue<slam::Scan> scans(settings.queue_capacity);
  // With refinement the odometry runs ahead while a stretch is registered: a deeper queue.
  BoundedQueue<PlacedScan> placed(settings.refine ? 4 * settings.queue_capacity
                                                  : settings.queue_capacity);
  BoundedQueue<PlacedScan> refined(settings.queue_capacity);
  BoundedQueue<LocatedScan> located(settings.queue_capacity);
  const Clock::time_point start = Clock::now();

  // Each stage closes its output when it ends, so the next one drains and ends too; a
  // failing stage abandons its input so the one before it cannot block on a full queue.
  std::thread reader([&] {
    guarded(state, [&] { read_scans(source, settings.range, scans, state, result); });
    scans.close();
  });
  std::thread front_end([&] {
    guarded(state, [&] {
      locate_scans(locator, settings.drop_mixed_pixels, scans, placed, state, result);
    });
    if (state.stopping()) scans.abandon();
    placed.close();
  });
  std::thread refinement;
  if (settings.refine) {
    refinement = std::thread([&] {
      guarded(state, [&] { refine_scans(*settings.refine, placed, refined, result); });
      if (state.stopping()) placed.abandon();
      refined.close();
    });
  }
  BoundedQueue<PlacedScan>& to_rays = settings.refine ? refined : placed;
  std::unique_ptr<LoopStage> loops;
  if (settings.loops) loops = std::make_unique<LoopStage>(*settings.loops, settings.relocalize);
  std::thread rays([&] {
    guarded(state, [&] { make_rays(to_rays, located, loops.get(), settings.integrate, result); });
    if (state.stopping()) to_rays.abandon();
    located.close();
  });
  guarded(state, [&] { MappingStage(open_map, settings, result).run(located); });
  located.abandon();
  refined.abandon();
  placed.abandon();
  scans.abandon();
  rays.join();
  if (refinement.joinable()) refinement.join();
  front_end.join();
  reader.join();
  if (loops) {
    // On a stop too: the keyframes queued are few, and the corrected path is worth having.
    if (state.stopping() && !StopSignal::requested()) loops->abandon();
    guarded(state, [&] {
      const Clock::time_point loops_start = Clock::now();
      result.loops = loops->finish();
      result.timings.loops_finish_ms = ms_since(loops_start);
    });
  }

  result.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  result.interrupted = StopSignal::requested();
  if (!result.poses.empty()) {
    result.recording_s =
        static_cast<double>(result.poses.stamps_ns.back() - result.poses.stamps_ns.front()) * 1e-9;
  }
  const slam::ReadStats& read = source.stats();
  for (const std::string& warning : read.warnings) {
    if (result.warnings.size() < slam::ReadStats::kMaxKeptWarnings)
      result.warnings.push_back(warning);
  }
  result.warning_count += read.warning_count;
  state.rethrow_failure();
  return result;
}

}  // namespace featsense::app
