#pragma once
// Real time (a live sensor): the stages that may lag (the refinement, the rays, the TSDF, the
// loop closure) run below the odometry, which must keep the sensor's pace. Each runs on a
// thread of its own at a lower scheduling priority, its parallel loops kept to a task arena
// that leaves a core to the odometry: on a small computer the odometry gets the CPU when it
// needs it, and the rest takes what is left (the policy of map_pipeline.hpp then skips
// integrations and keyframes instead of holding the odometry up).

#include <tbb/task_arena.h>

namespace featsense::mapping {

/// How much lower than the odometry (Linux nice increments): the refinement a little (its
/// queue holds the odometry up once full), the stages that skip work when behind more.
inline constexpr int kRefinementNice = 5;
inline constexpr int kBackgroundNice = 10;

class BackgroundThread {
 public:
  /// Lowers the calling thread's priority by `nice_increment` (best effort: left as it is
  /// where the system refuses) and prepares an arena of all cores but one (at least one).
  explicit BackgroundThread(int nice_increment);

  /// Runs `work` on this thread, its parallel loops inside the arena.
  template <typename Work>
  void run(const Work& work) {
    arena_.execute(work);
  }

 private:
  tbb::task_arena arena_;
};

}  // namespace featsense::mapping
