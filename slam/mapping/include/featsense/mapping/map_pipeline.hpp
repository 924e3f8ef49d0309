#pragma once
// The threaded pipeline that drives a map pass over a recording: a reader thread, a front-end
// thread (the scan locator), with refinement a refinement thread (the poses made final a
// stretch at a time), a thread that turns placed scans into rays (and hands keyframes to the
// loop closure's own thread) and the calling thread, which integrates (shift, TSDF, periodic
// flush of the store); joined by bounded queues. A full queue makes the stage before it wait,
// so memory stays bounded however fast the reader is; a failing stage stops the others, the
// map written so far is flushed and the error rethrown once every thread has joined.
//
// A live sensor cannot be made to wait. With PassSettings::real_time the odometry is kept at
// the sensor's pace. The stages after it run below it (background_thread.hpp: lower thread
// priorities, and parallel loops that leave a core to the odometry; the TSDF then on a
// thread of its own), and this policy decides what they give up, each step counted
// (PassResult::real_time):
//   1. The TSDF falls behind (its queue of 4 x queue_capacity scans full, deep enough for a
//      refined stretch handed out at once and a map shift): the next scans are placed but not
//      integrated,
//      their poses kept, until it has room again; it thus integrates every k-th scan for as
//      long as it needs, and no rays are made for the others.
//   2. The loop closure falls behind (8 keyframes queued): keyframes are skipped.
//   3. The refinement falls behind: its queue (16 x queue_capacity scans) absorbs a stretch
//      that takes long; half full, the refinement makes no clouds of the scans it takes, so
//      that a stretch without them passes with the last stretch's correction, unregistered,
//      and the queue drains; only once it is full all the same the odometry waits for it, and
//      then step 4 drops scans.
//   4. Last resort, the odometry falls behind (its queue of queue_capacity scans full): the
//      oldest waiting scan is dropped unplaced, so the freshest scan is the next one placed.
// The reader never waits, so the sensor's packets are never left in the socket buffers.

#include <cstddef>
#include <cstdint>
#include <optional>

#include "featsense/mapping/map_pass.hpp"
#include "featsense/mapping/pass_result.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::mapping {

/// Which scans of the recording to map: frame indices (0-based, as scan.sequence) and/or
/// seconds after the first scan; both ends inclusive.
struct FrameRange {
  std::optional<uint64_t> first_frame;
  std::optional<uint64_t> last_frame;
  std::optional<double> first_s;
  std::optional<double> last_s;
  /// Stamps (the scans' clock): a session of a map mapped again keeps to its own scans.
  std::optional<int64_t> first_stamp_ns;
  std::optional<int64_t> last_stamp_ns;
};

struct PipelineSettings {
  size_t queue_capacity = 4;  ///< scans per queue (four times that before a refinement)
  FrameRange range;
};

/// Runs the stages of `pass` over `source` until the source ends, the range ends or the pass's
/// stop token is set; the source's warnings join the pass's. The pass stays open (close it,
/// or finish the Mapper it belongs to). Where a stage fails, the pass is abandoned (what was
/// integrated is flushed) and the first error is rethrown after every thread joined.
void drive_pass(slam::ScanSource& source, MapPass& pass, const PipelineSettings& settings = {});

/// drive_pass, then the pass closed: its result.
PassResult run_pipeline(slam::ScanSource& source, MapPass& pass,
                        const PipelineSettings& settings = {});

/// A whole pass over `source` with `locator`: made (the store of `store` opened), run by the
/// pipeline and closed. `config` holds a continued map's voxel size and tau already.
PassResult run_pass(slam::ScanSource& source, slam::ScanLocator& locator,
                    const PassSettings& settings, const config::Config& config,
                    const MapStoreRequest& store, const RunEvents& events,
                    const PipelineSettings& pipeline = {});

}  // namespace featsense::mapping
