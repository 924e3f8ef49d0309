#pragma once
/// The triangles of each of the 256 sign configurations of a cube, derived at start-up from
/// the cube's geometry rather than typed in as a table.
///
/// Corner c sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1); bit c of a case is set when
/// corner c is negative (value < 0, inside). Edge e runs along axis e / 4 from its lower
/// corner edge_lower_corner(e). On a face with four sign changes the negative corners are
/// cut off separately; the rule depends on signs only, so two cubes sharing a face always
/// agree and the surface has no cracks.

#include <array>
#include <cstdint>

namespace featsense::mesh::internal {

constexpr int kMaxCaseTriangles = 12;

struct CubeCase {
  int triangle_count = 0;
  /// Edge ids, three per triangle, counter-clockwise seen from the positive side.
  std::array<std::array<int8_t, 3>, kMaxCaseTriangles> triangles{};
};

/// The 256 cases, built once (thread-safe).
const std::array<CubeCase, 256>& cube_cases();

/// Axis (0 = x, 1 = y, 2 = z) of edge e.
constexpr int edge_axis(int edge) { return edge / 4; }

/// Offset (0 or 1 per axis, as a corner index) of the lower end of edge e.
constexpr int edge_lower_corner(int edge) {
  const int axis = edge / 4;
  const int a = edge & 1;         // first perpendicular axis offset
  const int b = (edge >> 1) & 1;  // second perpendicular axis offset
  // The perpendicular axes in increasing order: x -> (y, z), y -> (x, z), z -> (x, y).
  if (axis == 0) return (a << 1) | (b << 2);
  if (axis == 1) return a | (b << 2);
  return a | (b << 1);
}

}  // namespace featsense::mesh::internal
