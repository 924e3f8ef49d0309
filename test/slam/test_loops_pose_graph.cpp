#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/loops/pose_graph.hpp"
#include "featsense/slam/loops/trajectory_correction.hpp"

namespace featsense::slam::loops {
namespace {

using test::pose;

constexpr double kDegree = M_PI / 180.0;

/// Twice round a 20 x 20 m square, a node every metre, and an odometry that drifts: 0.1 deg of
/// yaw and 1 cm sideways per metre, with a little noise.
struct DriftingSquare {
  std::vector<Eigen::Isometry3d> truth;
  std::vector<Eigen::Isometry3d> odometry;

  DriftingSquare() {
    for (int lap = 0; lap < 2; ++lap) {
      for (int side = 0; side < 4; ++side) {
        for (int step = 0; step < 20; ++step) {
          const double yaw = side * M_PI / 2.0;
          const Eigen::Vector2d corner[4] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}};
          const Eigen::Vector2d at =
              corner[side] + step * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
          truth.push_back(pose(yaw, 0.0, 0.0, {at.x(), at.y(), 1.0 + 0.1 * lap}));
        }
      }
    }
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.002);
    odometry.push_back(truth.front());
    for (size_t i = 1; i < truth.size(); ++i) {
      const Eigen::Isometry3d step = truth[i - 1].inverse() * truth[i];
      const Eigen::Isometry3d drift = pose(0.1 * M_PI / 180.0 + noise(rng), 0.0, 0.0,
                                           {noise(rng), 0.01 + noise(rng), noise(rng)});
      odometry.push_back(odometry.back() * step * drift);
    }
  }

  double rmse(const std::vector<Eigen::Isometry3d>& poses) const {
    double sum = 0.0;
    for (size_t i = 0; i < truth.size(); ++i)
      sum += (poses[i].translation() - truth[i].translation()).squaredNorm();
    return std::sqrt(sum / static_cast<double>(truth.size()));
  }
};

Matrix6d information(double sigma_rad, double sigma_m) {
  Matrix6d I = Matrix6d::Zero();
  I.diagonal().head<3>().setConstant(1.0 / (sigma_rad * sigma_rad));
  I.diagonal().tail<3>().setConstant(1.0 / (sigma_m * sigma_m));
  return I;
}

/// The square's graph: odometry edges, and loops from each node of the second lap to the
/// same corner of the first, measured from the truth.
PoseGraph square_graph(const DriftingSquare& square, int loop_every) {
  PoseGraph graph;
  for (const Eigen::Isometry3d& T : square.odometry) graph.add_node(T);
  for (size_t i = 1; i < square.odometry.size(); ++i) {
    graph.add_edge({i - 1, i, square.odometry[i - 1].inverse() * square.odometry[i],
                    information(0.01, 0.05), false});
  }
  const size_t lap = square.truth.size() / 2;
  for (size_t i = lap; i < square.truth.size(); i += static_cast<size_t>(loop_every)) {
    graph.add_edge({i - lap, i, square.truth[i - lap].inverse() * square.truth[i],
                    information(0.002, 0.02), true});
  }
  return graph;
}

TEST(PoseGraph, RecoversASquarePathFromItsLoops) {
  const DriftingSquare square;
  const double before = square.rmse(square.odometry);
  PoseGraph graph = square_graph(square, 10);
  const PoseGraphSummary summary = graph.optimize();
  const double after = square.rmse(graph.poses());
  EXPECT_GT(before, 1.0);  // the drift is real: metres after 160 m
  EXPECT_LT(after, 0.1 * before) << "before " << before;
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  ASSERT_EQ(summary.loop_weights.size(), 8u);
  for (double w : summary.loop_weights) EXPECT_GT(w, 0.5);
  // The first node is the map frame: it does not move.
  EXPECT_LT((graph.pose(0).translation() - square.truth[0].translation()).norm(), 1e-9);
}

TEST(PoseGraph, AWrongLoopIsOverruledByTheOthers) {
  const DriftingSquare square;
  PoseGraph right = square_graph(square, 10);
  right.optimize();
  const double without = square.rmse(right.poses());
  PoseGraph wrong = square_graph(square, 10);
  // Node 150 said to be where node 30 is: 20 m and half a turn off the truth.
  wrong.add_edge({30, 150, Eigen::Isometry3d::Identity(), information(0.002, 0.02), true});
  const PoseGraphSummary summary = wrong.optimize();
  const double with = square.rmse(wrong.poses());
  EXPECT_LT(with, 1.1 * without + 0.01) << "without " << without;
  ASSERT_EQ(summary.loop_weights.size(), 9u);
  EXPECT_LT(summary.loop_weights.back(), 0.01);
  for (size_t i = 0; i + 1 < summary.loop_weights.size(); ++i)
    EXPECT_GT(summary.loop_weights[i], 0.5) << i;
}

TEST(PoseGraph, EdgeErrorIsTheLeftPerturbation) {
  const Eigen::Isometry3d measured = pose(0.3, -0.1, 0.2, {1.0, -2.0, 0.5});
  const Eigen::Isometry3d from = pose(1.0, 0.1, 0.0, {3.0, 4.0, 5.0});
  // The estimate moved by a small rotation w and translation v on the left of the
  // measurement.
  const Eigen::Vector3d w(0.01, -0.02, 0.015);
  const Eigen::Vector3d v(0.1, 0.05, -0.2);
  Eigen::Isometry3d perturbed = Eigen::Isometry3d::Identity();
  perturbed.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  perturbed.translation() = v;
  const Eigen::Isometry3d to = from * perturbed * measured;
  const Eigen::Matrix<double, 6, 1> e = edge_error(from, to, measured);
  EXPECT_LT((e.head<3>() - w).norm(), 1e-12);
  EXPECT_LT((e.tail<3>() - v).norm(), 1e-12);
}

TEST(PoseGraph, RejectsBadEdges) {
  PoseGraph graph;
  graph.add_node(Eigen::Isometry3d::Identity());
  graph.add_node(Eigen::Isometry3d::Identity());
  EXPECT_THROW(graph.add_edge({0, 2, Eigen::Isometry3d::Identity(), Matrix6d::Identity(), false}),
               std::invalid_argument);
  EXPECT_THROW(graph.add_edge({1, 1, Eigen::Isometry3d::Identity(), Matrix6d::Identity(), false}),
               std::invalid_argument);
  EXPECT_THROW(graph.add_edge({0, 1, Eigen::Isometry3d::Identity(), -Matrix6d::Identity(), false}),
               std::invalid_argument);
  Matrix6d nan = Matrix6d::Identity();
  nan(2, 3) = NAN;
  EXPECT_THROW(graph.add_edge({0, 1, Eigen::Isometry3d::Identity(), nan, false}),
               std::invalid_argument);
  // A graph without edges optimises to itself.
  EXPECT_TRUE(graph.optimize().converged);
}

/// Twice round a 20 x 20 m square whose odometry tilts: 0.02 deg of pitch and 0.01 deg of roll
/// per metre (a path that bends up), and an IMU's up direction at each node, with an
/// accelerometer bias `bias` in the sensor frame. The odometry starts in a frame tilted by
/// `frame_tilt` from the vertical (`truth` is in it too, `level_truth` is not).
struct TiltingSquare {
  std::vector<Eigen::Isometry3d> level_truth;
  std::vector<Eigen::Isometry3d> truth;
  std::vector<Eigen::Isometry3d> odometry;
  std::vector<GravityObservation> gravity;

  TiltingSquare(const Eigen::Vector3d& bias, const Eigen::Isometry3d& frame_tilt) {
    const DriftingSquare square;
    level_truth = square.truth;
    for (const Eigen::Isometry3d& T : square.truth) truth.push_back(frame_tilt * T);
    odometry.push_back(truth.front());
    const Eigen::Isometry3d drift = pose(0.0, 0.02 * kDegree, 0.01 * kDegree, {0, 0, 0});
    for (size_t i = 1; i < truth.size(); ++i)
      odometry.push_back(odometry.back() * truth[i - 1].inverse() * truth[i] * drift);
    for (size_t i = 0; i < truth.size(); ++i) {
      GravityObservation o;
      o.node = i;
      // Gravity is vertical in the untilted frame: R_world_sensor^T (g up) + bias.
      const Eigen::Matrix3d R_world_sensor =
          frame_tilt.rotation().transpose() * truth[i].rotation();
      o.mean_force = R_world_sensor.transpose() * Eigen::Vector3d(0, 0, 9.81) + bias;
      o.sigma_rad = 0.005 * kDegree;
      gravity.push_back(o);
    }
  }

  PoseGraph graph(bool with_gravity) const {
    PoseGraph g;
    for (const Eigen::Isometry3d& T : odometry) g.add_node(T);
    for (size_t i = 1; i < odometry.size(); ++i) {
      g.add_edge(
          {i - 1, i, odometry[i - 1].inverse() * odometry[i], information(0.001, 0.01), false});
    }
    if (with_gravity) {
      for (const GravityObservation& o : gravity) g.add_gravity(o, 0.2);
    }
    return g;
  }

  /// The largest tilt of a node from its true attitude in the vertical frame, degrees (the
  /// angle between the true and the estimated up directions).
  double worst_tilt_deg(const std::vector<Eigen::Isometry3d>& poses) const {
    double worst = 0.0;
    for (size_t i = 0; i < truth.size(); ++i) {
      const Eigen::Vector3d up_true =
          level_truth[i].rotation().transpose() * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d up = poses[i].rotation().transpose() * Eigen::Vector3d::UnitZ();
      worst = std::max(worst, std::acos(std::clamp(up.dot(up_true), -1.0, 1.0)) / kDegree);
    }
    return worst;
  }
};

TEST(PoseGraph, GravityLevelsAnOdometryThatTilts) {
  const TiltingSquare square(Eigen::Vector3d::Zero(), Eigen::Isometry3d::Identity());
  PoseGraph without = square.graph(false);
  without.optimize();
  PoseGraph with = square.graph(true);
  const PoseGraphSummary summary = with.optimize();
  // The drift turns with the path round the square: up to 0.6 deg.
  EXPECT_GT(square.worst_tilt_deg(without.poses()), 0.3);
  EXPECT_LT(square.worst_tilt_deg(with.poses()), 0.02);
  EXPECT_EQ(summary.gravity.observations, square.truth.size());
  // The first node was level: the graph levelled the map by no more than its drift allows.
  EXPECT_LT(summary.gravity.map_tilt_deg.norm(), 0.02);
}

TEST(PoseGraph, GravityFindsTheAccelerometersBiasOnceThePathTurns) {
  const Eigen::Vector3d bias(0.15, -0.1, 0.0);
  const TiltingSquare square(bias, Eigen::Isometry3d::Identity());
  PoseGraph graph = square.graph(true);
  const PoseGraphSummary summary = graph.optimize();
  // A bias of 0.18 m/s^2 read as gravity would lean every node by about 1 degree.
  EXPECT_LT((summary.gravity.accel_bias_mps2 - bias).head<2>().norm(), 0.005);
  EXPECT_LT(square.worst_tilt_deg(graph.poses()), 0.03);
}

TEST(PoseGraph, GravityTellsTheMapFramesTilt) {
  // The first node, held fixed, stands 1.5 degrees off the vertical (the map frame is the
  // first scan's): the graph finds the tilt and levels the poses, the first node's position
  // and heading kept.
  const Eigen::Isometry3d tilt = pose(0.0, 1.5 * kDegree, 0.0, {0, 0, 0});
  const TiltingSquare square(Eigen::Vector3d::Zero(), tilt);
  PoseGraph graph = square.graph(true);
  const PoseGraphSummary summary = graph.optimize();
  EXPECT_NEAR(summary.gravity.map_tilt_deg.norm(), 1.5, 0.02);
  EXPECT_GT(summary.gravity.levelled_deg, 1.45);  // the square's turns tell the bias apart
  EXPECT_LT(square.worst_tilt_deg(graph.poses()), 0.02);
  EXPECT_LT((graph.pose(0).translation() - square.truth[0].translation()).norm(), 1e-9);
  const Eigen::Vector3d heading = graph.pose(0).rotation() * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d heading_true = square.truth[0].rotation() * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(heading.y(), heading.x()), std::atan2(heading_true.y(), heading_true.x()),
              1e-3);
}

TEST(PoseGraph, GravityDoesNotLevelByABiasItCannotTellFromATilt) {
  // A straight path: the accelerometer's bias (0.1 m/s^2 forward) looks like a tilt of 0.58 deg
  // that nothing tells apart. The first node is level; the graph must not tilt the map by it.
  PoseGraph graph;
  const size_t n = 40;
  for (size_t i = 0; i < n; ++i) graph.add_node(pose(0.0, 0.0, 0.0, {double(i), 0.0, 1.0}));
  for (size_t i = 1; i < n; ++i)
    graph.add_edge({i - 1, i, pose(0.0, 0.0, 0.0, {1, 0, 0}), information(0.001, 0.01), false});
  for (size_t i = 0; i < n; ++i) {
    GravityObservation o;
    o.node = i;
    o.mean_force = Eigen::Vector3d(0.1, 0.0, 9.81);
    o.sigma_rad = 0.005 * kDegree;
    graph.add_gravity(o, 0.2);
  }
  const PoseGraphSummary summary = graph.optimize();
  EXPECT_GT(summary.gravity.tilt_sigma_deg, 0.5);  // about 0.2 / 9.81 rad
  EXPECT_LT(summary.gravity.levelled_deg, 0.05);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d up = graph.pose(i).rotation() * Eigen::Vector3d::UnitZ();
    EXPECT_LT(std::acos(std::min(1.0, up.z())) / kDegree, 0.05) << i;
  }
}

TEST(PoseGraph, RejectsBadGravity) {
  PoseGraph graph;
  graph.add_node(Eigen::Isometry3d::Identity());
  GravityObservation o;
  o.mean_force = Eigen::Vector3d(0, 0, 9.81);
  o.sigma_rad = 0.001;
  o.node = 1;
  EXPECT_THROW(graph.add_gravity(o, 0.2), std::invalid_argument);
  o.node = 0;
  o.sigma_rad = 0.0;
  EXPECT_THROW(graph.add_gravity(o, 0.2), std::invalid_argument);
  o.sigma_rad = 0.001;
  o.mean_force = Eigen::Vector3d(NAN, 0, 9.81);
  EXPECT_THROW(graph.add_gravity(o, 0.2), std::invalid_argument);
}

/// The square's truth with every odometry turn off by 0.06 deg about a random axis (a LiDAR
/// that wobbles, as a drone's does), its graph sigma saying so, and a gyroscope that turns
/// within 0.006 deg a keyframe once its bias is taken out.
struct WobblingSquare {
  DriftingSquare square;
  std::vector<Eigen::Isometry3d> odometry;
  std::vector<GyroObservation> gyro;
  Eigen::Vector3d bias{0.001, -0.0005, 0.0008};

  WobblingSquare() {
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.001);
    odometry.push_back(square.truth.front());
    for (size_t i = 1; i < square.truth.size(); ++i) {
      const Eigen::Isometry3d step = square.truth[i - 1].inverse() * square.truth[i];
      Eigen::Isometry3d wobble = Eigen::Isometry3d::Identity();
      const Eigen::Vector3d w(noise(rng), noise(rng), noise(rng));
      wobble.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      odometry.push_back(odometry.back() * step * wobble);
      // 0.5 s between keyframes: the bias turns the gyroscope's reading by J b, J = 0.5 I.
      GyroObservation o;
      o.from = i - 1;
      o.to = i;
      o.bias_jacobian = 0.5 * Eigen::Matrix3d::Identity();
      const Eigen::Vector3d turn = o.bias_jacobian * bias;
      o.delta =
          step.rotation() * Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix();
      o.sigma_rad.setConstant(1e-4);
      o.noise_rad = 1e-4;
      gyro.push_back(o);
    }
  }

  PoseGraph graph(bool with_gyro) const {
    PoseGraph g;
    for (const Eigen::Isometry3d& T : odometry) g.add_node(T);
    for (size_t i = 1; i < odometry.size(); ++i)
      g.add_edge(
          {i - 1, i, odometry[i - 1].inverse() * odometry[i], information(0.001, 0.01), false});
    if (with_gyro)
      for (const GyroObservation& o : gyro) g.add_gyro(o, 0.02);
    return g;
  }

  /// The largest error of the turn over five keyframes, degrees. (Over the whole run the
  /// gyroscope's bias is known only as well as the LiDAR's turns average it: the absolute
  /// attitude drifts either way.)
  double worst_deg(const std::vector<Eigen::Isometry3d>& poses) const {
    double worst = 0.0;
    for (size_t i = 0; i + 5 < poses.size(); ++i)
      worst = std::max(worst, test::angle_between(poses[i].inverse() * poses[i + 5],
                                                  square.truth[i].inverse() * square.truth[i + 5]) /
                                  kDegree);
    return worst;
  }
};

TEST(PoseGraph, TheGyroscopeHoldsTheTurnsTheLidarWobbles) {
  const WobblingSquare wobbling;
  PoseGraph without = wobbling.graph(false);
  without.optimize();
  PoseGraph with = wobbling.graph(true);
  const PoseGraphSummary summary = with.optimize();
  // Five wobbles of 0.1 deg (three axes): 0.2 deg and more.
  const double worst_without = wobbling.worst_deg(without.poses());
  const double worst_with = wobbling.worst_deg(with.poses());
  RecordProperty("worst_without_deg", std::to_string(worst_without));
  RecordProperty("worst_with_deg", std::to_string(worst_with));
  EXPECT_GT(worst_without, 0.2);
  EXPECT_LT(worst_with, 0.1);
  EXPECT_EQ(summary.gyro_edges, wobbling.gyro.size());
  // The bias from 159 LiDAR turns of 1e-3 rad over 0.5 s each: 1.6e-4 rad/s per axis.
  EXPECT_LT((summary.gyro_bias_radps - wobbling.bias).norm(), 5e-4);
}

TEST(PoseGraph, RejectsBadGyroscopeEdges) {
  PoseGraph graph;
  graph.add_node(Eigen::Isometry3d::Identity());
  graph.add_node(Eigen::Isometry3d::Identity());
  GyroObservation o;
  o.from = 0;
  o.to = 2;
  o.sigma_rad.setConstant(1e-3);
  EXPECT_THROW(graph.add_gyro(o, 0.02), std::invalid_argument);
  o.to = 0;
  EXPECT_THROW(graph.add_gyro(o, 0.02), std::invalid_argument);
  o.to = 1;
  o.sigma_rad.x() = 0.0;
  EXPECT_THROW(graph.add_gyro(o, 0.02), std::invalid_argument);
  o.sigma_rad.x() = 1e-3;
  o.delta(0, 0) = NAN;
  EXPECT_THROW(graph.add_gyro(o, 0.02), std::invalid_argument);
  o.delta = Eigen::Matrix3d::Identity();
  EXPECT_THROW(graph.add_gyro(o, 0.0), std::invalid_argument);
  EXPECT_NO_THROW(graph.add_gyro(o, 0.02));
}

TEST(TrajectoryCorrection, IsContinuousAndExactAtKeyframes) {
  TrajectoryCorrection correction;
  const Eigen::Isometry3d a_before = pose(0.0, 0.0, 0.0, {0, 0, 0});
  const Eigen::Isometry3d a_after = pose(0.02, 0.0, 0.0, {0.1, 0, 0});
  const Eigen::Isometry3d b_before = pose(0.5, 0.0, 0.0, {10, 0, 0});
  const Eigen::Isometry3d b_after = pose(0.45, 0.01, 0.0, {10.3, -0.2, 0.05});
  correction.add_keyframe(0.0, a_before, a_after);
  correction.add_keyframe(10.0, b_before, b_after);
  EXPECT_TRUE(correction.apply(0.0, a_before).isApprox(a_after, 1e-9));
  EXPECT_TRUE(correction.apply(10.0, b_before).isApprox(b_after, 1e-9));
  // Before the first and after the last keyframe: their corrections.
  EXPECT_TRUE(correction.correction_at(-5.0).isApprox(correction.correction_at(0.0), 1e-12));
  EXPECT_TRUE(correction.correction_at(15.0).isApprox(correction.correction_at(10.0), 1e-12));
  // No jump anywhere: a millimetre along the path changes the correction by little.
  for (double s = -1.0; s < 11.0; s += 0.05) {
    const Eigen::Isometry3d here = correction.correction_at(s);
    const Eigen::Isometry3d next = correction.correction_at(s + 1e-3);
    EXPECT_LT((here.translation() - next.translation()).norm(), 1e-4) << s;
    EXPECT_LT(test::angle_between(here, next), 1e-5) << s;
  }
  EXPECT_THROW(correction.add_keyframe(5.0, a_before, a_after), std::invalid_argument);
  EXPECT_TRUE(TrajectoryCorrection().correction_at(3.0).isApprox(Eigen::Isometry3d::Identity()));
}

}  // namespace
}  // namespace featsense::slam::loops
