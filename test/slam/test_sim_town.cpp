// The `town` scene and its paths: the twin blocks alike, `loop` coming back to earlier places
// in both directions, `drive` never, every path clear of buildings and parked cars.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "featsense/slam/sim/ray_caster.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/sim/trajectory.hpp"

namespace featsense::slam {
namespace {

/// A path sampled every `step_s`: positions, yaw, time and distance travelled.
struct Sample {
  Eigen::Vector3d p;
  double yaw_rad;
  double t_s;
  double s_m;
};

std::vector<Sample> sample_path(const std::string& scene, const std::string& name,
                                double step_s = 0.25) {
  const NamedPath path = scene_path(scene, name);
  const auto trajectory = make_spline_trajectory(path.waypoints_m, path.speed_mps, path.tilt);
  std::vector<Sample> out;
  for (double t = 0.0; t <= trajectory->duration_s(); t += step_s) {
    const Eigen::Isometry3d T = trajectory->pose(t);
    out.push_back(
        {T.translation(), std::atan2(T.linear()(1, 0), T.linear()(0, 0)), t, t * path.speed_mps});
  }
  return out;
}

double heading_difference_deg(double a, double b) {
  return std::abs(std::remainder(a - b, 2.0 * M_PI)) * 180.0 / M_PI;
}

/// Metres of path that come back within `radius_m` of a place passed more than `gap_m`
/// before, with a heading that `heading_ok(difference in degrees)` accepts.
template <typename HeadingOk>
double revisited_m(const std::vector<Sample>& path, double gap_m, double radius_m,
                   HeadingOk heading_ok) {
  double total = 0.0;
  for (size_t j = 1; j < path.size(); ++j) {
    for (size_t i = 0; i < j && path[j].s_m - path[i].s_m > gap_m; ++i) {
      if ((path[j].p - path[i].p).head<2>().norm() < radius_m &&
          heading_ok(heading_difference_deg(path[i].yaw_rad, path[j].yaw_rad))) {
        total += path[j].s_m - path[j - 1].s_m;
        break;
      }
    }
  }
  return total;
}

/// The triangles (not the road) whose centres lie in the box from `lo`, in coordinates
/// relative to `lo`.
std::vector<std::array<Eigen::Vector3f, 3>> triangles_in(const mesh::TriangleMesh& m,
                                                         const Eigen::Vector2f& lo,
                                                         const Eigen::Vector2f& size) {
  std::vector<std::array<Eigen::Vector3f, 3>> out;
  const Eigen::Vector3f origin(lo.x(), lo.y(), 0.0f);
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    if (m.parts[m.triangle_part[t]].name == "asphalt") continue;
    std::array<Eigen::Vector3f, 3> corners;
    for (int k = 0; k < 3; ++k)
      corners[k] = m.vertices[static_cast<size_t>(m.triangles[t][k])] - origin;
    const Eigen::Vector2f centre = (corners[0] + corners[1] + corners[2]).head<2>() / 3.0f;
    if ((centre.array() >= 0.0f).all() && (centre.array() <= size.array()).all())
      out.push_back(corners);
  }
  return out;
}

/// How many triangles of `a` have a match in `b` (each used once): the same corners within
/// 1 mm (the rounding of moved coordinates), found through a 5 cm grid of their centres.
size_t matching_triangles(const std::vector<std::array<Eigen::Vector3f, 3>>& a,
                          const std::vector<std::array<Eigen::Vector3f, 3>>& b) {
  constexpr float kCellM = 0.05f;
  const auto cell = [&](const std::array<Eigen::Vector3f, 3>& t) {
    const Eigen::Vector3f c = (t[0] + t[1] + t[2]) / (3.0f * kCellM);
    return std::array<long, 3>{std::lround(c.x()), std::lround(c.y()), std::lround(c.z())};
  };
  std::map<std::array<long, 3>, std::vector<size_t>> grid;
  for (size_t i = 0; i < b.size(); ++i) grid[cell(b[i])].push_back(i);
  std::vector<bool> used(b.size(), false);
  size_t matched = 0;
  for (const auto& t : a) {
    const std::array<long, 3> c = cell(t);
    bool found = false;
    for (long dx = -1; dx <= 1 && !found; ++dx) {
      for (long dy = -1; dy <= 1 && !found; ++dy) {
        for (long dz = -1; dz <= 1 && !found; ++dz) {
          const auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == grid.end()) continue;
          for (size_t i : it->second) {
            bool same = !used[i];
            for (int k = 0; k < 3 && same; ++k)
              same = (t[k] - b[i][k]).cwiseAbs().maxCoeff() < 1e-3f;
            if (same) {
              used[i] = found = true;
              break;
            }
          }
        }
      }
    }
    matched += found;
  }
  return matched;
}

TEST(SimTown, TwinBlocksAreTheSameGeometryMoved) {
  const mesh::TriangleMesh town = build_scene("town");
  // Blocks (0, 1) and (2, 1), each with its half of the streets around it (parked cars, light
  // poles' arms), but not the lanes in the middle.
  const Eigen::Vector2f size(46.0f, 46.0f);
  const auto a = triangles_in(town, {2.0f, 52.0f}, size);
  const auto b = triangles_in(town, {102.0f, 52.0f}, size);
  EXPECT_GT(a.size(), 3000u);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(matching_triangles(a, b), a.size());
  // Another block is not like them.
  const auto other = triangles_in(town, {52.0f, 52.0f}, size);
  EXPECT_LT(matching_triangles(a, other), a.size() / 2);
}

TEST(SimTown, LoopComesBackInBothDirections) {
  const std::vector<Sample> loop = sample_path("town", "loop");
  const double length = loop.back().s_m;
  EXPECT_GT(length, 800.0);
  EXPECT_LT(length, 1300.0);
  EXPECT_LT((loop.back().p - loop.front().p).norm(), 5.0);  // ends where it began
  // Streets driven again more than 200 m later, within 3 m (lanes of opposite directions are
  // 2.5 m apart): some 100 m the same way, some 90 m the other way.
  const double same = revisited_m(loop, 200.0, 3.0, [](double turn) { return turn < 30.0; });
  const double opposite = revisited_m(loop, 200.0, 3.0, [](double turn) { return turn > 150.0; });
  EXPECT_GT(same, 80.0);
  EXPECT_GT(opposite, 60.0);
}

TEST(SimTown, DriveNeverComesBack) {
  const std::vector<Sample> drive = sample_path("town", "drive");
  EXPECT_GT(drive.back().s_m, 300.0);
  for (size_t i = 0; i < drive.size(); ++i) {
    for (size_t j = i + 1; j < drive.size(); ++j) {
      if (drive[j].t_s - drive[i].t_s <= 30.0) continue;
      ASSERT_GT((drive[j].p - drive[i].p).head<2>().norm(), 20.0)
          << "t = " << drive[i].t_s << " and " << drive[j].t_s << " s";
    }
  }
}

TEST(SimTown, ParkingLoopLapsTheSameWay) {
  const std::vector<Sample> loop = sample_path("parking", "loop");
  EXPECT_GT(revisited_m(loop, 50.0, 2.0, [](double turn) { return turn < 30.0; }), 40.0);
}

TEST(SimTown, PathsKeepClearOfBuildingsAndParkedCars) {
  const mesh::TriangleMesh town = build_scene("town");
  const RayCaster caster(town);
  for (const std::string& name : path_names("town")) {
    for (const Sample& sample : sample_path("town", name)) {
      // Nothing within 2.5 m, horizontally, at the sensor's height or 1.2 m lower (car roofs).
      for (const double below : {0.0, 1.2}) {
        for (int k = 0; k < 16; ++k) {
          Ray ray;
          ray.origin = (sample.p - Eigen::Vector3d(0, 0, below)).cast<float>();
          ray.direction = Eigen::Vector3f(std::cos(k * M_PI / 8), std::sin(k * M_PI / 8), 0);
          ray.max_distance_m = 2.5f;
          ASSERT_FALSE(caster.intersect(ray).hit())
              << name << " comes close to something at t = " << sample.t_s << " s, ("
              << sample.p.transpose() << ")";
        }
      }
    }
  }
}

TEST(SimTown, UnknownNamesAreErrorsThatListTheChoices) {
  EXPECT_EQ(path_names("town"), (std::vector<std::string>{"loop", "drive", "walk"}));
  try {
    scene_path("town", "drone");
    FAIL() << "no drone path in town";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("loop, drive, walk"), std::string::npos) << e.what();
  }
  EXPECT_THROW(path_names("moon"), std::invalid_argument);
  EXPECT_THROW(scene_path("lab", "loop"), std::invalid_argument);
}

}  // namespace
}  // namespace featsense::slam
