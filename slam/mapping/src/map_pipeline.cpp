#include "featsense/mapping/map_pipeline.hpp"

#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "background_thread.hpp"
#include "featsense/mapping/bounded_queue.hpp"

namespace featsense::mapping {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// What the stages share: the first error and whether to stop.
class PipelineState {
 public:
  explicit PipelineState(const MapPass& pass) : pass_(pass) {}
  bool failed() const { return failed_.load(); }
  bool stopping() const { return failed() || pass_.stop_requested(); }

  void fail(std::exception_ptr error) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) error_ = error;
    failed_.store(true);
  }
  std::exception_ptr failure() const { return error_; }

 private:
  const MapPass& pass_;
  std::mutex mutex_;
  std::atomic<bool> failed_{false};
  std::exception_ptr error_;
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

/// guarded(), below the odometry in real time (background_thread.hpp); call it on the stage's
/// own thread.
template <typename Work>
void guarded_stage(PipelineState& state, bool real_time, int nice_increment, const Work& work) {
  if (!real_time) return guarded(state, work);
  guarded(state, [&] { BackgroundThread(nice_increment).run(work); });
}

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

/// Real time: the scan goes in line without waiting; where the line was full its oldest scan
/// is dropped, counted by what held the odometry up. False once the line is closed.
bool push_never_waiting(slam::Scan scan, MapPass& pass, BoundedQueue<slam::Scan>& out,
                        const BoundedQueue<PlacedScan>& to_refinement) {
  slam::Scan dropped;
  switch (out.push_dropping_oldest(std::move(scan), &dropped)) {
    case BoundedQueue<slam::Scan>::Pushed::kQueued:
      return true;
    case BoundedQueue<slam::Scan>::Pushed::kDroppedOldest:
      pass.count_dropped(dropped.sequence, pass.refines() && to_refinement.full()
                                               ? ScanDrop::kRefinementBehind
                                               : ScanDrop::kOdometryBehind);
      return true;
    case BoundedQueue<slam::Scan>::Pushed::kClosed:
      break;
  }
  return false;
}

void read_scans(slam::ScanSource& source, const FrameRange& range, MapPass& pass,
                BoundedQueue<slam::Scan>& out, const BoundedQueue<PlacedScan>& to_refinement,
                const PipelineState& state) {
  std::optional<int64_t> first_stamp_ns;
  while (!state.stopping()) {
    const Clock::time_point start = Clock::now();
    std::optional<slam::Scan> scan = source.next();
    if (!scan) break;
    pass.count_read();
    if (!first_stamp_ns) first_stamp_ns = scan->stamp_ns;
    if (after_range(*scan, range, *first_stamp_ns)) break;
    if (before_range(*scan, range, *first_stamp_ns)) {
      pass.count_before_range();
      continue;
    }
    pass.add_read_time(ms_since(start));
    pass.mark_ready(scan->sequence);
    const bool queued = pass.real_time()
                            ? push_never_waiting(std::move(*scan), pass, out, to_refinement)
                            : out.push(std::move(*scan));
    if (!queued) break;
  }
}

void locate_scans(MapPass& pass, BoundedQueue<slam::Scan>& in, BoundedQueue<PlacedScan>& out) {
  while (std::optional<slam::Scan> scan = in.pop()) {
    std::optional<PlacedScan> placed = pass.locate(std::move(*scan));
    if (placed && !out.push(std::move(*placed))) break;
  }
}

bool push_all(std::vector<PlacedScan> scans, BoundedQueue<PlacedScan>& out) {
  for (PlacedScan& scan : scans) {
    if (!out.push(std::move(scan))) return false;
  }
  return true;
}

/// The refinement holds each stretch's scans until their poses are final; the queue before
/// it is deep enough that the odometry does not wait while a stretch is registered. Real
/// time: with its queue half full it makes no clouds (step 3 of the policy), so that it
/// catches up rather than hold the odometry up.
void refine_scans(MapPass& pass, BoundedQueue<PlacedScan>& in, BoundedQueue<PlacedScan>& out) {
  while (std::optional<PlacedScan> placed = in.pop()) {
    const bool behind = pass.real_time() && 2 * in.size() >= in.capacity();
    if (!push_all(pass.refine(std::move(*placed), behind), out)) break;
  }
  // The end of the input, or a stop: the last stretch is refined and mapped too.
  push_all(pass.finish_refinement(), out);
}

/// Rays in a stage of their own: with odometry the front end is the pipeline's slowest
/// stage, and the deskewing of every point need not wait for it. The poses are final here:
/// the loop closure sees each scan too. Real time: while the TSDF's line is full, scans go on
/// as poses only (this is the line's one producer: found not full, it takes the scan at once).
void make_rays(MapPass& pass, BoundedQueue<PlacedScan>& in, BoundedQueue<LocatedScan>& out) {
  while (std::optional<PlacedScan> placed = in.pop()) {
    const bool skip = pass.real_time() && out.full();
    std::optional<LocatedScan> located = pass.make_rays(std::move(*placed), skip);
    if (!located) break;
    const bool queued =
        skip ? out.push_past_capacity(std::move(*located)) : out.push(std::move(*located));
    if (!queued) break;
  }
}

void integrate_scans(MapPass& pass, BoundedQueue<LocatedScan>& in) {
  while (std::optional<LocatedScan> scan = in.pop()) pass.integrate(std::move(*scan));
}

}  // namespace

void drive_pass(slam::ScanSource& source, MapPass& pass, const PipelineSettings& settings) {
  pass.set_total_frames(source.info().frames);
  PipelineState state(pass);
  BoundedQueue<slam::Scan> scans(settings.queue_capacity);
  // Before a refinement the odometry runs ahead while a stretch is registered: a deeper queue,
  // deeper still in real time, where the odometry must not wait for a stretch that takes long.
  const bool real_time = pass.real_time();
  const size_t refine_depth = (real_time ? 16 : 4) * settings.queue_capacity;
  BoundedQueue<PlacedScan> placed(pass.refines() ? refine_depth : settings.queue_capacity);
  BoundedQueue<PlacedScan> refined(settings.queue_capacity);
  // Real time: the refinement hands out a stretch's scans at once, and the map pauses for its
  // shifts and flushes; a deeper queue rides those out, so that only a TSDF that is really
  // behind has integrations skipped.
  BoundedQueue<LocatedScan> located((real_time ? 4 : 1) * settings.queue_capacity);

  // Each stage closes its output when it ends, so the next one drains and ends too; a
  // failing stage abandons its input so the one before it cannot block on a full queue.
  std::thread reader([&] {
    guarded(state, [&] { read_scans(source, settings.range, pass, scans, placed, state); });
    scans.close();
  });
  std::thread front_end([&] {
    guarded(state, [&] { locate_scans(pass, scans, placed); });
    if (state.stopping()) scans.abandon();
    placed.close();
  });
  std::thread refinement;
  if (pass.refines()) {
    refinement = std::thread([&] {
      guarded_stage(state, real_time, kRefinementNice,
                    [&] { refine_scans(pass, placed, refined); });
      if (state.stopping()) placed.abandon();
      refined.close();
    });
  }
  BoundedQueue<PlacedScan>& to_rays = pass.refines() ? refined : placed;
  std::thread rays([&] {
    guarded_stage(state, real_time, kBackgroundNice, [&] { make_rays(pass, to_rays, located); });
    if (state.stopping()) to_rays.abandon();
    located.close();
  });
  if (real_time) {
    // On a thread of its own, whose lowered priority ends with it.
    std::thread mapping([&] {
      guarded_stage(state, true, kBackgroundNice, [&] { integrate_scans(pass, located); });
    });
    mapping.join();
  } else {
    guarded(state, [&] { integrate_scans(pass, located); });
  }
  located.abandon();
  refined.abandon();
  placed.abandon();
  scans.abandon();
  rays.join();
  if (refinement.joinable()) refinement.join();
  front_end.join();
  reader.join();
  if (state.failed()) {
    pass.abandon();
    std::rethrow_exception(state.failure());
  }
  pass.add_source_warnings(source.stats());
}

PassResult run_pipeline(slam::ScanSource& source, MapPass& pass, const PipelineSettings& settings) {
  drive_pass(source, pass, settings);
  return pass.close();
}

PassResult run_pass(slam::ScanSource& source, slam::ScanLocator& locator,
                    const PassSettings& settings, const config::Config& config,
                    const MapStoreRequest& store, const RunEvents& events,
                    const PipelineSettings& pipeline) {
  MapPass pass(locator, settings, config, source.info().sensor, store, events);
  return run_pipeline(source, pass, pipeline);
}

}  // namespace featsense::mapping
