#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/loops/relocalizer.hpp"
#include "featsense/slam/loops/session_links.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "scene_sampling.hpp"

namespace featsense::slam::loops {
namespace {

using test::pose;

/// A map of one session: a keyframe every 2 m along the parking lot's middle lane, eastbound.
std::vector<MapKeyframe> lane_map(const mesh::TriangleMesh& scene, uint32_t session,
                                  const std::vector<Eigen::Isometry3d>& poses,
                                  int points_each = 6000) {
  std::vector<MapKeyframe> map;
  for (size_t i = 0; i < poses.size(); ++i) {
    MapKeyframe keyframe;
    keyframe.session = session;
    keyframe.index = static_cast<uint32_t>(i);
    keyframe.stamp_ns = static_cast<int64_t>(i) * 400'000'000;
    keyframe.T_map_sensor = poses[i];
    const std::vector<Eigen::Vector3f> points =
        test::keyframe_scan_at(scene, poses[i], 100 + session * 1000 + i, points_each);
    keyframe.descriptor = make_scan_context(points);  // level poses: the sensor frame is level
    keyframe.cloud = CompactCloud(points);
    map.push_back(std::move(keyframe));
  }
  travelled_from_positions(map);
  return map;
}

std::vector<Eigen::Isometry3d> eastbound(double from_x, double to_x) {
  std::vector<Eigen::Isometry3d> poses;
  for (double x = from_x; x <= to_x; x += 2.0) poses.push_back(pose(0.0, 0.0, 0.0, {x, 10.5, 1.9}));
  return poses;
}

/// Westbound in the north lane: the map's places seen the other way round.
std::vector<Eigen::Isometry3d> westbound(double from_x, double to_x) {
  std::vector<Eigen::Isometry3d> poses;
  for (double x = from_x; x >= to_x; x -= 2.0)
    poses.push_back(pose(M_PI, 0.0, 0.0, {x, 12.0, 1.9}));
  return poses;
}

TEST(Relocalizer, PlacesARecordingThatStartsFarAwayTurnedTheOtherWay) {
  const mesh::TriangleMesh scene = build_scene("parking");
  Relocalizer relocalizer(lane_map(scene, 0, eastbound(6.0, 58.0)), RelocalizeSettings{});
  // The new recording starts 44 m from the map's first keyframe, turned 180 degrees: its own
  // frame is its first pose.
  const std::vector<Eigen::Isometry3d> truth = westbound(50.0, 20.0);
  const Eigen::Isometry3d T_map_session = truth.front();
  std::optional<Relocalization> placed;
  for (size_t k = 0; k < truth.size() && !placed; ++k) {
    placed = relocalizer.add_keyframe(
        static_cast<int64_t>(k) * 400'000'000, T_map_session.inverse() * truth[k], 2.0 * k,
        test::keyframe_scan_at(scene, truth[k], static_cast<uint32_t>(k)));
  }
  ASSERT_TRUE(placed) << relocalizer.counts().candidates << " candidates, "
                      << relocalizer.counts().verified << " verified";
  EXPECT_GE(placed->agreeing, 2u);  // one match is a guess
  EXPECT_LT((placed->T_map_session.translation() - T_map_session.translation()).norm(), 0.1);
  EXPECT_LT(
      rotation_angle_deg(placed->T_map_session.rotation().transpose() * T_map_session.rotation()),
      1.0);
}

TEST(Relocalizer, DoesNotPlaceARecordingOfAnotherPlace) {
  const mesh::TriangleMesh parking = build_scene("parking");
  const mesh::TriangleMesh corridor = build_scene("corridor");
  Relocalizer relocalizer(lane_map(parking, 0, eastbound(6.0, 58.0)), RelocalizeSettings{});
  for (size_t k = 0; k < 20; ++k) {
    const Eigen::Isometry3d T = pose(0.0, 0.0, 0.0, {2.0 + 2.0 * k, 0.0, 1.5});
    EXPECT_FALSE(
        relocalizer.add_keyframe(static_cast<int64_t>(k) * 1'000'000'000, T, 2.0 * k,
                                 test::keyframe_scan_at(corridor, T, static_cast<uint32_t>(k))));
  }
  EXPECT_EQ(relocalizer.counts().keyframes, 20u);
}

TEST(Relocalizer, AGuessOutsideTheMapPlacesNothing) {
  // A user's guess is verified like any match: one that puts the recording where the map has
  // no keyframe adds no candidate, and the descriptor still finds the true place.
  const mesh::TriangleMesh scene = build_scene("parking");
  RelocalizeSettings settings;
  settings.guess = pose(0.0, 0.0, 0.0, {500.0, 500.0, 0.0});
  Relocalizer relocalizer(lane_map(scene, 0, eastbound(6.0, 58.0)), settings);
  const std::vector<Eigen::Isometry3d> truth = eastbound(20.0, 40.0);
  std::optional<Relocalization> placed;
  for (size_t k = 0; k < truth.size() && !placed; ++k) {
    placed = relocalizer.add_keyframe(
        static_cast<int64_t>(k) * 400'000'000, truth.front().inverse() * truth[k], 2.0 * k,
        test::keyframe_scan_at(scene, truth[k], static_cast<uint32_t>(50 + k)));
  }
  ASSERT_TRUE(placed);
  EXPECT_EQ(placed->found_by, "descriptor");
  EXPECT_LT((placed->T_map_session.translation() - truth.front().translation()).norm(), 0.1);
}

TEST(Relocalizer, AGuessThatNarrowsTheSearchTakesNoPlaceFarFromIt) {
  // A place elsewhere that looks alike: a verifier that, from any candidate, finds the
  // recording 30 m along the lane from where it is (the true place is not in the map, the
  // look-alike is). A guess that only adds its places lets the look-alike place the recording;
  // one that narrows the search does not, and places it where the verifier finds the truth,
  // but not turned the other way.
  const mesh::TriangleMesh scene = build_scene("parking");
  const std::vector<Eigen::Isometry3d> truth = eastbound(10.0, 24.0);
  size_t k = 0;
  double found_along_m = 30.0;
  bool turned = false;
  const PlaceVerifier look_alike = [&](const Eigen::Isometry3d&, const refine::GaussianCloud&) {
    PlaceCheck check;
    Eigen::Isometry3d found = pose(0.0, 0.0, 0.0, {found_along_m, 0.0, 0.0}) * truth[k];
    if (turned) found.linear() = found.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ());
    check.T_map_query = found;
    check.inlier_fraction = 0.8;
    return check;
  };
  const auto run = [&](bool guess_only, double guess_off_m) {
    RelocalizeSettings settings;
    // The session's frame is its first pose: the guess of T_map_session is that pose.
    settings.guess = pose(0.0, 0.0, 0.0, {guess_off_m, 0.0, 0.0}) * truth.front();
    settings.guess_only = guess_only;
    Relocalizer relocalizer(lane_map(scene, 0, eastbound(6.0, 58.0)), settings, look_alike);
    std::optional<Relocalization> placed;
    for (k = 0; k < truth.size() && !placed; ++k) {
      placed = relocalizer.add_keyframe(
          static_cast<int64_t>(k) * 400'000'000, truth.front().inverse() * truth[k], 2.0 * k,
          test::keyframe_scan_at(scene, truth[k], static_cast<uint32_t>(k)));
    }
    return std::make_pair(placed, relocalizer.counts());
  };
  const auto [added, added_counts] = run(false, 0.0);
  ASSERT_TRUE(added);
  EXPECT_NEAR(added->T_map_session.translation().x() - truth.front().translation().x(), 30.0, 1e-9);

  const auto [narrowed, narrowed_counts] = run(true, 0.0);
  EXPECT_FALSE(narrowed);
  EXPECT_EQ(narrowed_counts.verified, 0u);
  EXPECT_EQ(narrowed_counts.rejected.at("away from the guess"), narrowed_counts.candidates);

  // Where the verifier finds the truth, a guess 3 m off it narrows the search to it.
  found_along_m = 0.0;
  const auto [found, found_counts] = run(true, 3.0);
  ASSERT_TRUE(found);
  EXPECT_LT((found->T_map_session.translation() - truth.front().translation()).norm(), 1e-9);

  // ... and where it finds the same street seen the other way, that is no match either.
  turned = true;
  const auto [reversed, reversed_counts] = run(true, 0.0);
  EXPECT_FALSE(reversed);
  EXPECT_EQ(reversed_counts.verified, 0u);
}

TEST(Relocalizer, AVerifierChecksTheCandidatesInPlaceOfTheMapKeyframes) {
  // A verifier (a localizer's registration to the map's surface) decides each candidate: here
  // one that knows the truth, takes a guess within 6 m of it and gives the true place.
  const mesh::TriangleMesh scene = build_scene("parking");
  const std::vector<Eigen::Isometry3d> truth = westbound(50.0, 20.0);
  size_t k = 0;
  size_t calls = 0;
  const PlaceVerifier knows_the_truth = [&](const Eigen::Isometry3d& guess,
                                            const refine::GaussianCloud& cloud) {
    ++calls;
    EXPECT_GT(cloud.size(), 100u);
    PlaceCheck check;
    if ((guess.translation() - truth[k].translation()).norm() > 6.0) {
      check.rejection = "elsewhere";
      return check;
    }
    check.T_map_query = truth[k];
    check.inlier_fraction = 0.8;
    return check;
  };
  Relocalizer relocalizer(lane_map(scene, 0, eastbound(6.0, 58.0)), RelocalizeSettings{},
                          knows_the_truth);
  std::optional<Relocalization> placed;
  for (k = 0; k < truth.size() && !placed; ++k) {
    placed = relocalizer.add_keyframe(
        static_cast<int64_t>(k) * 400'000'000, truth.front().inverse() * truth[k], 2.0 * k,
        test::keyframe_scan_at(scene, truth[k], static_cast<uint32_t>(k)));
  }
  ASSERT_TRUE(placed);
  EXPECT_EQ(calls, relocalizer.counts().candidates);  // every candidate, by the verifier
  // The place is the verifier's, exactly.
  EXPECT_LT((placed->T_map_session.translation() - truth.front().translation()).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(placed->inlier_fraction, 0.8);

  // A verifier that finds nothing anywhere: nothing placed, its reason counted.
  Relocalizer refuses(lane_map(scene, 0, eastbound(6.0, 58.0)), RelocalizeSettings{},
                      [](const Eigen::Isometry3d&, const refine::GaussianCloud&) {
                        PlaceCheck check;
                        check.rejection = "no surface";
                        return check;
                      });
  for (size_t j = 0; j < truth.size(); ++j) {
    EXPECT_FALSE(refuses.add_keyframe(
        static_cast<int64_t>(j) * 400'000'000, truth.front().inverse() * truth[j], 2.0 * j,
        test::keyframe_scan_at(scene, truth[j], static_cast<uint32_t>(j))));
  }
  EXPECT_EQ(refuses.counts().verified, 0u);
  EXPECT_EQ(refuses.counts().rejected.at("no surface"), refuses.counts().candidates);
}

TEST(Relocalizer, AnAmbiguousKeyframeIsConfirmedByTheNextOneThatIsNot) {
  // The first keyframe fits the truth and, nearly as well, a place 8 m along the lane (a
  // block like another one); the second fits the truth alone. The first's places stay
  // hypotheses: the second picks the true one and, with it, makes two keyframes that agree.
  const mesh::TriangleMesh scene = build_scene("parking");
  const std::vector<Eigen::Isometry3d> truth = eastbound(20.0, 40.0);
  size_t k = 0;
  bool both_ambiguous = false;
  const PlaceVerifier twin_at_first = [&](const Eigen::Isometry3d& guess,
                                          const refine::GaussianCloud&) {
    PlaceCheck check;
    if ((guess.translation() - truth[k].translation()).norm() <= 3.0) {
      check.T_map_query = truth[k];
      check.inlier_fraction = 0.8;
    } else if (k == 0 || both_ambiguous) {
      check.T_map_query = pose(0.0, 0.0, 0.0, {8.0, 0.0, 0.0}) * truth[k];
      check.inlier_fraction = 0.75;
    } else {
      check.rejection = "elsewhere";
    }
    return check;
  };
  const auto run = [&](Relocalizer& relocalizer, size_t keyframes) {
    std::optional<Relocalization> placed;
    for (k = 0; k < keyframes && !placed; ++k) {
      placed = relocalizer.add_keyframe(
          static_cast<int64_t>(k) * 400'000'000, truth.front().inverse() * truth[k], 2.0 * k,
          test::keyframe_scan_at(scene, truth[k], static_cast<uint32_t>(k)));
    }
    return placed;
  };
  Relocalizer relocalizer(lane_map(scene, 0, eastbound(6.0, 58.0)), RelocalizeSettings{},
                          twin_at_first);
  const std::optional<Relocalization> placed = run(relocalizer, truth.size());
  ASSERT_TRUE(placed);
  EXPECT_EQ(placed->keyframe, 1u);
  EXPECT_EQ(placed->agreeing, 2u);
  EXPECT_GT(relocalizer.counts().rejected.at("ambiguous"), 0u);
  EXPECT_LT((placed->T_map_session.translation() - truth.front().translation()).norm(), 1e-9);

  // Where every keyframe is ambiguous, none places the session, however many agree.
  both_ambiguous = true;
  Relocalizer twins(lane_map(scene, 0, eastbound(6.0, 58.0)), RelocalizeSettings{}, twin_at_first);
  EXPECT_FALSE(run(twins, truth.size()));
  EXPECT_EQ(twins.counts().keyframes, truth.size());
}

TEST(SessionLinks, ALaterSessionPlacedOffIsPulledOntoTheFirst) {
  const mesh::TriangleMesh scene = build_scene("parking");
  std::vector<MapKeyframe> keyframes = lane_map(scene, 0, eastbound(6.0, 58.0));
  const size_t first_later = keyframes.size();
  // The second session, the other way round, placed 0.3 m and 0.5 degree off (as a match of
  // its first keyframes may place it), its odometry drifting 1 cm sideways per metre.
  const std::vector<Eigen::Isometry3d> truth = westbound(30.0, 6.0);
  const Eigen::Isometry3d off = pose(0.5 * M_PI / 180.0, 0.0, 0.0, {0.2, -0.2, 0.05});
  Eigen::Isometry3d estimate = truth.front() * off;
  std::vector<MapKeyframe> later = lane_map(scene, 1, truth);
  for (size_t k = 0; k < later.size(); ++k) {
    if (k > 0)
      estimate =
          estimate * (truth[k - 1].inverse() * truth[k]) * pose(0.0, 0.0, 0.0, {0.0, 0.02, 0.0});
    later[k].T_map_sensor = estimate;
  }
  for (MapKeyframe& k : later) keyframes.push_back(std::move(k));
  const SessionLinkResult linked = link_sessions(keyframes, SessionLinkSettings{}, 1u);
  EXPECT_GE(linked.links.size(), 3u);
  EXPECT_TRUE(linked.unlinked_sessions.empty());
  double worst_m = 0.0;
  for (size_t k = 0; k < truth.size(); ++k) {
    worst_m = std::max(
        worst_m, (linked.poses[first_later + k].translation() - truth[k].translation()).norm());
  }
  EXPECT_LT(worst_m, 0.1);
  // The first session, made consistent by its own loops, stays where it was, within what the
  // two sessions' registrations tell apart.
  for (size_t k = 0; k < first_later; ++k)
    EXPECT_LT((linked.poses[k].translation() - keyframes[k].T_map_sensor.translation()).norm(),
              0.05);
}

TEST(SessionLinks, ASessionLinkedAtEveryKeyframeKeepsItsShape) {
  // Each link moves the rest of the session, and the next link is measured from the poses it
  // moved. A pose that is a product of poses is off SO(3) by rounding (here 1e-9, as a scale);
  // that must not build up over the links into a scale that stretches the session's clouds
  // until no registration fits them.
  const mesh::TriangleMesh scene = build_scene("parking");
  const std::vector<Eigen::Isometry3d> truth = eastbound(6.0, 58.0);
  // Denser samplings than a keyframe's: every registration fits well, so that only the
  // poses can make one fail.
  std::vector<MapKeyframe> keyframes = lane_map(scene, 0, truth, 20000);
  const size_t first_later = keyframes.size();
  std::vector<MapKeyframe> later = lane_map(scene, 1, truth, 20000);
  Eigen::Isometry3d off = pose(0.2 * M_PI / 180.0, 0.0, 0.0, {0.1, -0.1, 0.02});
  off.linear() *= 1.0 + 1e-9;
  for (MapKeyframe& k : later) {
    k.T_map_sensor = off * k.T_map_sensor;
    keyframes.push_back(std::move(k));
  }
  SessionLinkSettings settings;
  settings.loop.search_rest_m = 0.0;  // a link at every keyframe
  const SessionLinkResult linked = link_sessions(keyframes, settings, 1u);
  EXPECT_EQ(linked.links.size(), truth.size());
  EXPECT_TRUE(linked.rejected.empty());
  // The first link moves the session by its placement error; every later one by little.
  for (size_t k = 1; k < linked.links.size(); ++k) EXPECT_LT(linked.links[k].moved_m, 0.03) << k;
  for (size_t k = 0; k < truth.size(); ++k)
    EXPECT_LT((linked.poses[first_later + k].translation() - truth[k].translation()).norm(), 0.03);
}

}  // namespace
}  // namespace featsense::slam::loops
