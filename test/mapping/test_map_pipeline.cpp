// The threaded pipeline and the synchronous Mapper over the same stages: the same map either
// way, a stop token that ends a run with its map written, and a stage's failure that stops
// every thread and comes back as the error.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <thread>

#include "common/test_data.hpp"
#include "featsense/mapping/map_pipeline.hpp"
#include "featsense/mapping/mapper.hpp"
#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "mapping/mapping_test_scenes.hpp"

namespace featsense::mapping {
namespace {

#if defined(__SANITIZE_THREAD__)
/// Under ThreadSanitizer, TBB runs every parallel loop on the thread that calls it: Debian's
/// libtbb is not instrumented, so the hand-over of its tasks between worker threads would be
/// reported as races inside the TSDF integrator's loops. The pipeline's own threads, queues,
/// counters and callbacks stay as they are, and those are what these tests check.
class SerialTbb : public ::testing::Environment {
 public:
  void SetUp() override {
    control_ =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
  }
  void TearDown() override { control_.reset(); }

 private:
  std::unique_ptr<tbb::global_control> control_;
};
const ::testing::Environment* const kSerialTbb = ::testing::AddGlobalTestEnvironment(new SerialTbb);
#endif

using test::read_chunks;
using test::room_mapper_settings;
using test::small_room;

/// A source that hands out another's scans and calls `on_scan(k)` before the k-th.
class WatchedSource : public slam::ScanSource {
 public:
  WatchedSource(std::unique_ptr<slam::ScanSource> inner, std::function<void(size_t)> on_scan)
      : inner_(std::move(inner)), on_scan_(std::move(on_scan)) {}
  std::optional<slam::Scan> next() override {
    on_scan_(handed_out_++);
    return inner_->next();
  }
  const slam::SourceInfo& info() const override { return inner_->info(); }

 private:
  std::unique_ptr<slam::ScanSource> inner_;
  std::function<void(size_t)> on_scan_;
  size_t handed_out_ = 0;
};

/// A locator that places scans as the true path does, and throws at scan `fail_at`.
class FailingLocator : public slam::ScanLocator {
 public:
  FailingLocator(slam::Trajectory path, uint64_t fail_at)
      : inner_(slam::make_given_pose_locator(std::move(path), true)), fail_at_(fail_at) {}
  std::optional<slam::ScanPlacement> locate(const slam::Scan& scan, std::string& why) override {
    if (scan.sequence == fail_at_) throw std::runtime_error("locator broke at scan 5");
    return inner_->locate(scan, why);
  }
  std::string description() const override { return "failing"; }

 private:
  std::unique_ptr<slam::ScanLocator> inner_;
  uint64_t fail_at_;
};

/// A locator that places scans as the true path does, taking `delay` over each.
class SlowLocator : public slam::ScanLocator {
 public:
  SlowLocator(slam::Trajectory path, std::chrono::milliseconds delay)
      : inner_(slam::make_given_pose_locator(std::move(path), true)), delay_(delay) {}
  std::optional<slam::ScanPlacement> locate(const slam::Scan& scan, std::string& why) override {
    std::this_thread::sleep_for(delay_);
    return inner_->locate(scan, why);
  }
  std::string description() const override { return "slow"; }

 private:
  std::unique_ptr<slam::ScanLocator> inner_;
  std::chrono::milliseconds delay_;
};

TEST(MapPipeline, EachScansLatencyIsMeasuredFromItsSourceToTheMap) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_latency");
  const slam::BoxRoomSettings room = small_room(8);
  config::Config config = test::small_map_config();
  SlowLocator locator(test::room_path(room), std::chrono::milliseconds(30));
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  MapPass pass(locator, PassSettings{}, config, room.sensor,
               {dir / "map.h5", room.sensor.name, std::nullopt, false, {}, nullptr}, {});
  const PassResult result = run_pipeline(*source, pass);
  const StageTimings& t = result.timings;
  ASSERT_EQ(result.frames_mapped, 8u);
  // One figure per scan mapped, at each stage, in the order the scans were mapped.
  ASSERT_EQ(t.latency_pose_ms.size(), 8u);
  ASSERT_EQ(t.latency_final_pose_ms.size(), 8u);
  ASSERT_EQ(t.latency_integrated_ms.size(), 8u);
  for (size_t k = 0; k < 8; ++k) {
    // The front end took 30 ms over each; a scan waits for the ones before it as well.
    EXPECT_GE(t.latency_pose_ms[k], 29.0) << k;
    EXPECT_GE(t.latency_final_pose_ms[k], t.latency_pose_ms[k]) << k;
    EXPECT_GE(t.latency_integrated_ms[k], t.latency_final_pose_ms[k]) << k;
  }
}

/// A live sensor's pace: another source's scans, made first, then handed out `period` apart.
class PacedSource : public slam::ScanSource {
 public:
  PacedSource(std::unique_ptr<slam::ScanSource> inner, std::chrono::milliseconds period)
      : info_(inner->info()), period_(period) {
    while (std::optional<slam::Scan> scan = inner->next()) scans_.push_back(std::move(*scan));
  }
  std::optional<slam::Scan> next() override {
    std::this_thread::sleep_for(period_);
    if (next_ == scans_.size()) return std::nullopt;
    return std::move(scans_[next_++]);
  }
  const slam::SourceInfo& info() const override { return info_; }

 private:
  slam::SourceInfo info_;
  std::chrono::milliseconds period_;
  std::vector<slam::Scan> scans_;
  size_t next_ = 0;
};

/// The box room seen by a VLP-16: small scans, quick to make.
slam::BoxRoomSettings small_scans_room(int frames) {
  slam::BoxRoomSettings room = small_room(frames);
  room.sensor = config::sensor_preset("vlp16");
  return room;
}

PassSettings real_time_pass() {
  PassSettings settings;
  settings.real_time = true;
  return settings;
}

TEST(MapPipeline, InRealTimeAnOdometryThatFallsBehindLosesTheOldestScansCounted) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_real_time_odometry");
  const slam::BoxRoomSettings room = small_scans_room(24);
  config::Config config = test::small_map_config();
  // Scans 2 ms apart, 30 ms to place each: the odometry cannot keep up.
  SlowLocator locator(test::room_path(room), std::chrono::milliseconds(30));
  PacedSource source(slam::make_box_room_source(room), std::chrono::milliseconds(2));
  MapPass pass(locator, real_time_pass(), config, room.sensor,
               {dir / "map.h5", room.sensor.name, std::nullopt, false, {}, nullptr}, {});
  const PassResult result = run_pipeline(source, pass);
  const RealTimeCounts& kept_up = result.real_time;
  EXPECT_TRUE(kept_up.enabled);
  EXPECT_EQ(result.frames_read, 24u);  // the reader never waited for the odometry
  EXPECT_GT(kept_up.scans_dropped_odometry_behind, 0u);
  EXPECT_EQ(kept_up.scans_dropped_refinement_behind, 0u);  // no refinement in this pass
  // Every scan is accounted for: placed (integrated or not) or dropped, and every placed
  // scan has its pose.
  EXPECT_EQ(result.frames_mapped + kept_up.integrations_skipped + kept_up.scans_dropped(), 24u);
  EXPECT_EQ(result.poses.size(), 24u - kept_up.scans_dropped());
  // The oldest waiting scan is the one dropped: the last scan is always placed.
  EXPECT_EQ(result.poses.stamps_ns.back(),
            room.start_stamp_ns + static_cast<int64_t>(23 * 1e9 / room.sensor.rate_hz));
  for (const Eigen::Isometry3d& pose : result.poses.poses) EXPECT_TRUE(pose.matrix().allFinite());
  EXPECT_EQ(result.timings.latency_pose_ms.size(), result.poses.size());
}

TEST(MapPipeline, InRealTimeATsdfThatFallsBehindSkipsIntegrationsKeepingEveryPose) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_real_time_tsdf");
  const slam::BoxRoomSettings room = small_scans_room(30);
  config::Config config = test::small_map_config();
  const auto locator = slam::make_given_pose_locator(test::room_path(room), true);
  // Scans 15 ms apart; the mapping thread takes 150 ms more over each scan it integrates, so
  // its queue (16 scans) fills before the last scans come.
  RunEvents events;
  events.progress = [](const RunProgress&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
  };
  PacedSource source(slam::make_box_room_source(room), std::chrono::milliseconds(15));
  MapPass pass(*locator, real_time_pass(), config, room.sensor,
               {dir / "map.h5", room.sensor.name, std::nullopt, false, {}, nullptr}, events);
  const PassResult result = run_pipeline(source, pass);
  const RealTimeCounts& kept_up = result.real_time;
  // Placing is instant; the rays run below it, so on a busy machine a scan may still wait too
  // long for them and be dropped, counted. Every scan placed has its pose.
  EXPECT_LE(kept_up.scans_dropped(), 5u);
  const size_t placed = 30 - kept_up.scans_dropped();
  EXPECT_GT(kept_up.integrations_skipped, 0u);
  EXPECT_GT(result.frames_mapped, 0u);
  EXPECT_EQ(result.frames_mapped + kept_up.integrations_skipped, placed);
  // Every placed scan's pose, in order, whether integrated or not; the store keeps them all.
  ASSERT_EQ(result.poses.size(), placed);
  for (size_t k = 1; k < placed; ++k)
    EXPECT_GT(result.poses.stamps_ns[k], result.poses.stamps_ns[k - 1]);
  EXPECT_EQ(result.timings.latency_integrated_ms.size(), result.frames_mapped);
  EXPECT_FALSE(read_chunks(dir / "map.h5").empty());
  storage::Hdf5ChunkStore store(dir / "map.h5");
  EXPECT_EQ(store.read_trajectory().size(), placed);
}

TEST(MapPipeline, ARefinementBehindMakesNoCloudsAndKeepsTheLastCorrection) {
  // Step 3 of the real-time policy, stage by stage: the refinement told it is behind takes
  // each scan without its cloud; its stretches pass unregistered, every scan comes out once,
  // in order, at the pose it came with (the correction so far: none, with true poses).
  const std::filesystem::path dir = test::scratch_dir("pipeline_refinement_behind");
  const slam::BoxRoomSettings room = small_scans_room(24);
  config::Config config = test::small_map_config();
  const auto locator = slam::make_given_pose_locator(test::room_path(room), true);
  PassSettings settings = real_time_pass();
  slam::refine::RefineSettings refine;
  refine.distance_m = 0.3;
  refine.max_scans = 6;
  settings.refine = refine;
  MapPass pass(*locator, settings, config, room.sensor,
               {dir / "map.h5", room.sensor.name, std::nullopt, false, {}, nullptr}, {});
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  std::vector<PlacedScan> released;
  const auto keep = [&](std::vector<PlacedScan> scans) {
    for (PlacedScan& scan : scans) released.push_back(std::move(scan));
  };
  while (std::optional<slam::Scan> scan = source->next()) {
    std::optional<PlacedScan> placed = pass.locate(std::move(*scan));
    ASSERT_TRUE(placed);
    keep(pass.refine(std::move(*placed), /*behind=*/true));
  }
  keep(pass.finish_refinement());
  ASSERT_EQ(released.size(), 24u);
  for (size_t k = 1; k < released.size(); ++k)
    EXPECT_GT(released[k].placement.stamp_ns, released[k - 1].placement.stamp_ns);
  for (PlacedScan& scan : released) {
    const std::optional<LocatedScan> located = pass.make_rays(std::move(scan));
    ASSERT_TRUE(located);
    pass.integrate(*located);
  }
  const PassResult result = pass.close();
  // Only the first scan (which fixes the frame) had its cloud made.
  EXPECT_GT(result.real_time.refinement_clouds_skipped, 5u);
  EXPECT_EQ(result.refine.refined, 0u) << "a stretch without clouds is not registered";
  const slam::PoseInterpolator truth(test::room_path(room));
  for (size_t k = 0; k < result.poses.size(); ++k) {
    const std::optional<Eigen::Isometry3d> expected = truth.at(result.poses.stamps_ns[k]);
    ASSERT_TRUE(expected);
    EXPECT_LT((expected->translation() - result.poses.poses[k].translation()).norm(), 1e-6) << k;
  }
}

TEST(MapPipeline, WithoutRealTimeNothingIsSkippedHoweverSlowAStage) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_not_real_time");
  const slam::BoxRoomSettings room = small_scans_room(12);
  config::Config config = test::small_map_config();
  SlowLocator locator(test::room_path(room), std::chrono::milliseconds(10));
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  MapPass pass(locator, PassSettings{}, config, room.sensor,
               {dir / "map.h5", room.sensor.name, std::nullopt, false, {}, nullptr}, {});
  const PassResult result = run_pipeline(*source, pass);
  EXPECT_FALSE(result.real_time.enabled);
  EXPECT_EQ(result.frames_mapped, 12u);
  EXPECT_EQ(result.real_time.scans_dropped() + result.real_time.integrations_skipped, 0u);
}

TEST(MapPipeline, MakesTheSameMapAsAddingTheScansOneByOne) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_same_map");
  const slam::BoxRoomSettings room = small_room();

  Mapper threaded(room_mapper_settings(room, dir / "threaded.h5"));
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  const MapResult by_pipeline = map_source(*source, threaded);

  Mapper one_by_one(room_mapper_settings(room, dir / "synchronous.h5"));
  const std::unique_ptr<slam::ScanSource> again = slam::make_box_room_source(room);
  size_t mapped = 0;
  while (std::optional<slam::Scan> scan = again->next()) {
    const ScanUpdate update = one_by_one.add_scan(std::move(*scan));
    EXPECT_TRUE(update.placed) << update.why;
    EXPECT_EQ(update.scans_mapped, ++mapped) << "given poses are final at once";
  }
  const MapResult by_hand = one_by_one.finish();

  EXPECT_EQ(by_pipeline.mapped().frames_mapped, 12u);
  EXPECT_EQ(by_hand.mapped().frames_mapped, 12u);
  EXPECT_EQ(by_pipeline.final_poses.stamps_ns, by_hand.final_poses.stamps_ns);
  const auto threaded_chunks = read_chunks(dir / "threaded.h5");
  ASSERT_GT(threaded_chunks.size(), 10u);
  EXPECT_TRUE(threaded_chunks == read_chunks(dir / "synchronous.h5"))
      << "the pipeline and add_scan made different maps";
  EXPECT_EQ(by_pipeline.second_pass.kind, SecondPass::kNotNeeded);
  EXPECT_EQ(by_pipeline.loops_off_because, "the poses are given");
}

TEST(MapPipeline, TheOdometryRefinementAndLoopStagesGiveThePosesEitherWay) {
  // Every stage with a thread of its own: the odometry, the refinement (its stretch held to
  // the end), the loop closure's keyframes (a thread of the loop stage).
  const std::filesystem::path dir = test::scratch_dir("pipeline_odometry");
  const slam::BoxRoomSettings room = small_room(16);
  const auto settings = [&](const std::string& name) {
    MapperSettings s = room_mapper_settings(room, dir / name);
    s.given_poses.reset();
    s.T_map_first_scan = slam::box_room_pose(room, 0.0);
    return s;
  };
  Mapper threaded(settings("threaded.h5"));
  ASSERT_TRUE(threaded.estimates_poses());
  ASSERT_TRUE(threaded.loops_off_because().empty());
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  const MapResult by_pipeline = map_source(*source, threaded);

  Mapper one_by_one(settings("synchronous.h5"));
  const std::unique_ptr<slam::ScanSource> again = slam::make_box_room_source(room);
  while (std::optional<slam::Scan> scan = again->next()) one_by_one.add_scan(std::move(*scan));
  const MapResult by_hand = one_by_one.finish();

  ASSERT_EQ(by_pipeline.final_poses.size(), 16u);
  ASSERT_EQ(by_hand.final_poses.size(), 16u);
  ASSERT_TRUE(by_pipeline.first.loops.has_value());
  ASSERT_TRUE(by_pipeline.first.unrefined_poses.has_value());
  const slam::Trajectory truth = test::room_path(room);
  for (size_t i = 0; i < 16; ++i) {
    // The refinement's sums run in parallel: the two runs agree to rounding, not bit for bit.
    const Eigen::Vector3d threaded_at = by_pipeline.final_poses.poses[i].translation();
    const Eigen::Vector3d by_hand_at = by_hand.final_poses.poses[i].translation();
    EXPECT_LT((threaded_at - by_hand_at).norm(), 1e-6) << "scan " << i;
    // The room is analytic and the motion straight: the odometry follows it to millimetres.
    const int64_t stamp = by_pipeline.final_poses.stamps_ns[i];
    const double t = static_cast<double>(stamp - room.start_stamp_ns) * 1e-9;
    EXPECT_LT((threaded_at - slam::box_room_pose(room, t).translation()).norm(), 0.02)
        << "scan " << i;
  }
  EXPECT_GT(by_pipeline.first.loops->keyframes.size(), 0u);
}

TEST(MapPipeline, AStopTokenEndsTheRunWithItsMapWritten) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_stop");
  const slam::BoxRoomSettings room = small_room(40);
  RunEvents events;
  const StopToken stop = events.stop;
  Mapper mapper(room_mapper_settings(room, dir / "map.h5"), events);
  WatchedSource source(slam::make_box_room_source(room), [&](size_t k) {
    if (k == 6) stop.request_stop();
  });
  const MapResult result = map_source(source, mapper);
  EXPECT_TRUE(result.mapped().interrupted);
  EXPECT_GE(result.mapped().frames_mapped, 1u);
  EXPECT_LT(result.mapped().frames_mapped, 40u);
  // What was integrated is in the store, with the poses of the scans mapped.
  EXPECT_FALSE(read_chunks(dir / "map.h5").empty());
  storage::Hdf5ChunkStore store(dir / "map.h5");
  EXPECT_EQ(store.read_trajectory().size(), result.mapped().frames_mapped);
}

TEST(MapPipeline, AFailingStageStopsEveryThreadAndItsErrorComesBack) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_failure");
  const slam::BoxRoomSettings room = small_room(30);
  config::Config config = test::small_map_config();
  FailingLocator locator(test::room_path(room), 5);
  PassSettings settings;
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  MapPass pass(locator, settings, config, room.sensor,
               {dir / "map.h5", room.sensor.name, std::nullopt, false, {}, nullptr}, {});
  try {
    run_pipeline(*source, pass);
    FAIL() << "the pipeline hid the locator's failure";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "locator broke at scan 5");
  }
  // The scans before the failure were integrated and flushed: the file is readable.
  EXPECT_FALSE(read_chunks(dir / "map.h5").empty());
}

TEST(MapPipeline, ASourceThatFailsComesBackAsItsError) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_source_failure");
  const slam::BoxRoomSettings room = small_room(20);
  Mapper mapper(room_mapper_settings(room, dir / "map.h5"));
  WatchedSource source(slam::make_box_room_source(room), [](size_t k) {
    if (k == 3) throw slam::InputError("the recording ends in the middle of scan 3");
  });
  EXPECT_THROW(map_source(source, mapper), slam::InputError);
}

TEST(MapPipeline, ProgressComesFromOneThreadInOrder) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_progress");
  const slam::BoxRoomSettings room = small_room();
  RunEvents events;
  std::vector<size_t> mapped;
  std::atomic<int> callers{0};
  events.progress = [&](const RunProgress& at) {
    EXPECT_EQ(callers.fetch_add(1), 0) << "two progress callbacks at once";
    mapped.push_back(at.frames_mapped);
    EXPECT_EQ(at.total_frames, std::optional<size_t>(12));
    EXPECT_GE(at.frames_read, at.frames_mapped);
    callers.fetch_sub(1);
  };
  Mapper mapper(room_mapper_settings(room, dir / "map.h5"), events);
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  map_source(*source, mapper);
  ASSERT_EQ(mapped.size(), 12u);
  for (size_t i = 0; i < mapped.size(); ++i) EXPECT_EQ(mapped[i], i + 1);
}

TEST(MapPipeline, AMapperFinishedTwiceOrFedAfterItsEndSaysSo) {
  const std::filesystem::path dir = test::scratch_dir("pipeline_misuse");
  const slam::BoxRoomSettings room = small_room(3);
  Mapper mapper(room_mapper_settings(room, dir / "map.h5"));
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  while (std::optional<slam::Scan> scan = source->next()) mapper.add_scan(std::move(*scan));
  mapper.finish();
  EXPECT_THROW(mapper.finish(), std::logic_error);
  EXPECT_THROW(mapper.add_scan(slam::Scan::allocate(2, 2)), std::logic_error);
}

}  // namespace
}  // namespace featsense::mapping
