#include "internal/cube_cases.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

namespace featsense::mesh::internal {
namespace {

Eigen::Vector3d corner_position(int corner) {
  return {static_cast<double>(corner & 1), static_cast<double>((corner >> 1) & 1),
          static_cast<double>((corner >> 2) & 1)};
}

/// The edge joining two corners that differ along one axis.
int edge_between(int a, int b) {
  const int lower = std::min(a, b);
  const int axis = (a ^ b) == 1 ? 0 : ((a ^ b) == 2 ? 1 : 2);
  int first = 0;
  int second = 0;
  if (axis == 0) {
    first = (lower >> 1) & 1;
    second = (lower >> 2) & 1;
  } else if (axis == 1) {
    first = lower & 1;
    second = (lower >> 2) & 1;
  } else {
    first = lower & 1;
    second = (lower >> 1) & 1;
  }
  return axis * 4 + first + 2 * second;
}

/// The four corners of each face, counter-clockwise seen from outside the cube.
std::array<std::array<int, 4>, 6> faces_counter_clockwise() {
  std::array<std::array<int, 4>, 6> faces{};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      std::array<int, 4> corners{};
      int n = 0;
      for (int c = 0; c < 8; ++c) {
        if (((c >> axis) & 1) == side) corners[static_cast<size_t>(n++)] = c;
      }
      const Eigen::Vector3d outward = (side == 1 ? 1.0 : -1.0) * Eigen::Vector3d::Unit(axis);
      const Eigen::Vector3d t1 = Eigen::Vector3d::Unit((axis + 1) % 3);
      const Eigen::Vector3d t2 = outward.cross(t1);  // (t1, t2, outward) right-handed
      const Eigen::Vector3d centre(0.5, 0.5, 0.5);
      auto angle = [&](int c) {
        const Eigen::Vector3d d = corner_position(c) - centre;
        return std::atan2(d.dot(t2), d.dot(t1));
      };
      std::sort(corners.begin(), corners.end(), [&](int a, int b) { return angle(a) < angle(b); });
      faces[static_cast<size_t>(axis * 2 + side)] = corners;
    }
  }
  return faces;
}

/// Closed loops of crossing edges for one case. Walking a face's boundary counter-clockwise
/// (seen from outside), each sign change from positive to negative starts a segment that ends
/// at the next change back to positive: the segment cuts the negative corners it passes off
/// the face. An edge is walked in opposite directions by its two faces, so every crossing
/// starts exactly one segment and ends exactly one, and the segments close into loops.
std::vector<std::vector<int>> crossing_loops(int case_bits) {
  static const std::array<std::array<int, 4>, 6> faces = faces_counter_clockwise();
  auto negative = [case_bits](int corner) { return ((case_bits >> corner) & 1) != 0; };
  std::array<int, 12> next{};
  next.fill(-1);
  for (const auto& face : faces) {
    for (int k = 0; k < 4; ++k) {
      const int a = face[static_cast<size_t>(k)];
      const int b = face[static_cast<size_t>((k + 1) % 4)];
      if (negative(a) || !negative(b)) continue;  // not an entry into the negative side
      for (int step = 1; step < 4; ++step) {
        const int c = face[static_cast<size_t>((k + step) % 4)];
        const int d = face[static_cast<size_t>((k + step + 1) % 4)];
        if (negative(c) && !negative(d)) {
          next[static_cast<size_t>(edge_between(a, b))] = edge_between(c, d);
          break;
        }
      }
    }
  }
  std::vector<std::vector<int>> loops;
  std::array<bool, 12> used{};
  for (int start = 0; start < 12; ++start) {
    if (next[static_cast<size_t>(start)] < 0 || used[static_cast<size_t>(start)]) continue;
    std::vector<int> loop;
    for (int e = start; !used[static_cast<size_t>(e)]; e = next[static_cast<size_t>(e)]) {
      used[static_cast<size_t>(e)] = true;
      loop.push_back(e);
    }
    loops.push_back(loop);
  }
  return loops;
}

Eigen::Vector3d edge_midpoint(int edge) {
  return corner_position(edge_lower_corner(edge)) + 0.5 * Eigen::Vector3d::Unit(edge_axis(edge));
}

std::array<CubeCase, 256> build_cases() {
  std::array<CubeCase, 256> cases{};
  for (int bits = 0; bits < 256; ++bits) {
    CubeCase& out = cases[static_cast<size_t>(bits)];
    for (const std::vector<int>& loop : crossing_loops(bits)) {
      for (size_t i = 1; i + 1 < loop.size(); ++i) {  // a fan over the loop
        out.triangles[static_cast<size_t>(out.triangle_count++)] = {
            static_cast<int8_t>(loop[0]), static_cast<int8_t>(loop[i]),
            static_cast<int8_t>(loop[i + 1])};
      }
    }
  }
  // The walking rule fixes one orientation for every case; which one depends on conventions,
  // so look at the case of corner 0 alone inside and turn all triangles to face away from it.
  const auto& probe = cases[1].triangles[0];
  const Eigen::Vector3d a = edge_midpoint(probe[0]);
  const Eigen::Vector3d b = edge_midpoint(probe[1]);
  const Eigen::Vector3d c = edge_midpoint(probe[2]);
  if ((b - a).cross(c - a).dot(a - corner_position(0)) < 0.0) {
    for (CubeCase& cube_case : cases) {
      for (int t = 0; t < cube_case.triangle_count; ++t) {
        std::swap(cube_case.triangles[static_cast<size_t>(t)][1],
                  cube_case.triangles[static_cast<size_t>(t)][2]);
      }
    }
  }
  return cases;
}

}  // namespace

const std::array<CubeCase, 256>& cube_cases() {
  static const std::array<CubeCase, 256> cases = build_cases();
  return cases;
}

}  // namespace featsense::mesh::internal
