#pragma once
// Loop closure as a stage of the mapping pipeline: every scan whose pose is final passes
// through offer() (from the rays thread); a keyframe's points go to a thread of its own, where
// the loop closer searches, verifies and optimises, so that the pipeline does not wait for it
// unless it falls a few keyframes behind. At the end, where the input had an IMU, its gravity
// levels the graph too, and the corrections of the keyframes are spread over every scan's pose.

#include <atomic>
#include <exception>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "featsense/mapping/bounded_queue.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/loops/relocalizer.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::mapping {

struct LoopOutcome {
  std::vector<slam::loops::LoopRecord> loops;
  slam::loops::LoopCounts counts;
  slam::loops::PoseGraphSummary final_optimisation;
  /// Every scan offered: the pose it came with, and corrected by the keyframes around it.
  slam::Trajectory before;
  slam::Trajectory corrected;
  double corrections_max_m = 0.0;         ///< the largest move of a scan's position
  double keyframe_queue_wait_ms = 0.0;    ///< the pipeline's wait for the loop thread, in all
  std::vector<double> keyframe_cloud_ms;  ///< per keyframe: its points thinned for the closer
  /// Where the input had an IMU: gravity levelled the graph (observations > 0).
  slam::loops::GravityEstimate gravity;
  /// The keyframes at their final poses, for the map file (later sessions relocalize in them).
  std::vector<slam::loops::KeyframeRecord> keyframes;
  /// With a relocalizer: where the run was placed in the saved map (none: not placed), what
  /// was tried, and whether it gave up after its scans (the run was stopped there).
  std::optional<slam::loops::Relocalization> relocalization;
  slam::loops::RelocalizationCounts relocalize_counts;
  bool relocalize_gave_up = false;
  /// Whether the corrected poses differ from those the map was made with: loops were closed,
  /// gravity levelled the path or the gyroscope held its turns.
  bool corrects_poses() const {
    return !loops.empty() || gravity.observations > 0 || final_optimisation.gyro_edges > 0;
  }
};

/// Every pose of `path` (pose i taken `travelled_m[i]` metres along it) moved by the
/// keyframes' corrections around it.
slam::Trajectory corrected_path(const slam::loops::TrajectoryCorrection& correction,
                                const slam::Trajectory& path,
                                const std::vector<double>& travelled_m);

/// Relocalization in a saved map, alongside the loop closure: each keyframe of the first
/// `max_scans` scans goes to the relocalizer until it places the run.
struct RelocalizeStage {
  slam::loops::Relocalizer* relocalizer = nullptr;
  size_t max_scans = 0;
};

class LoopStage {
 public:
  /// `never_wait` (real time): a keyframe that finds the loop thread 8 keyframes behind is
  /// skipped, counted, rather than waited for.
  explicit LoopStage(const slam::loops::LoopSettings& settings,
                     std::optional<RelocalizeStage> relocalize = std::nullopt,
                     bool never_wait = false);
  ~LoopStage();
  LoopStage(const LoopStage&) = delete;
  LoopStage& operator=(const LoopStage&) = delete;

  /// The next scan whose pose is final, in order. False once the stage was abandoned, or the
  /// relocalization gave up (the run stops).
  bool offer(const slam::Scan& scan, const slam::ScanPlacement& placement);
  /// No more scans: the loop thread finishes the keyframes queued, the graph is optimised
  /// once more and every pose corrected. Rethrows the loop thread's failure.
  LoopOutcome finish();
  /// Stops the loop thread without waiting for what is queued (a failing pipeline).
  void abandon();

  /// After finish(): the loop closer, for a bench that adds a loop of its own, and every
  /// scan's pose corrected by the graph as it is then.
  slam::loops::LoopCloser& closer_after_finish();
  slam::Trajectory corrected() const;
  /// Keyframes skipped because the loop thread was behind (never_wait).
  size_t keyframes_skipped() const { return keyframes_skipped_; }

 private:
  struct KeyframeJob {
    int64_t stamp_ns = 0;
    double travelled_m = 0.0;
    Eigen::Isometry3d T_map_sensor;
    std::vector<Eigen::Vector3f> points;
    size_t scan = 0;  ///< how many scans were offered before it
  };
  void work();
  void take_keyframes();

  slam::loops::LoopSettings settings_;
  slam::loops::KeyframeSelector selector_;
  slam::loops::LoopCloser closer_;
  BoundedQueue<KeyframeJob> queue_;
  std::exception_ptr failure_;
  slam::Trajectory path_;
  std::vector<double> travelled_m_;
  std::vector<slam::ImuSample> imu_;  ///< every scan's, in order
  double wait_ms_ = 0.0;
  std::vector<double> cloud_ms_;
  bool finished_ = false;
  bool never_wait_ = false;
  size_t keyframes_skipped_ = 0;
  std::optional<RelocalizeStage> relocalize_;
  std::atomic<bool> relocalize_gave_up_{false};
  std::thread worker_;  ///< last: it starts once everything it uses is there
};

}  // namespace featsense::mapping
