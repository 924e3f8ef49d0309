#pragma once
/// The pieces the built-in scenes are made of (walls, furniture, trees, cars, light poles),
/// their materials, and the deterministic draw that places them; private to slam/sim.

#include <Eigen/Core>

#include <cstdint>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::slam::scene_parts {

using V = Eigen::Vector3f;

/// Diffuse reflectances at 865 nm (Ouster's wavelength), rounded typical values: vegetation
/// is bright in the near infrared, asphalt and glass dark.
struct Materials {
  static constexpr float kPlaster = 0.65f;
  static constexpr float kConcrete = 0.35f;
  static constexpr float kBrick = 0.45f;
  static constexpr float kFloorTiles = 0.4f;
  static constexpr float kWood = 0.45f;
  static constexpr float kMetal = 0.3f;
  static constexpr float kAsphalt = 0.08f;
  static constexpr float kGlass = 0.04f;
  static constexpr float kFoliage = 0.5f;
  static constexpr float kBark = 0.2f;
  static constexpr float kTyre = 0.03f;
};

/// A deterministic uniform draw in [lo, hi) for procedural placement: the same (stream, a,
/// b) gives the same number on every run and machine.
float draw(uint64_t stream, uint32_t a, uint32_t b, float lo, float hi);

/// Vertical walls: in the plane x = const from y0 to y1, or y = const from x0 to x1.
void add_wall_x(mesh::TriangleMesh& m, float x, float y0, float y1, float z0, float z1,
                uint32_t part);
void add_wall_y(mesh::TriangleMesh& m, float y, float x0, float x1, float z0, float z1,
                uint32_t part);

/// A table of 0.76 m over the rectangle (x0, y0)-(x1, y1): top and four legs.
void add_table(mesh::TriangleMesh& m, float x0, float y0, float x1, float y1, uint32_t part);
/// Open shelving: two side panels, a back panel and five shelves, front facing -y.
void add_shelving(mesh::TriangleMesh& m, float x0, float x1, float y0, float depth, uint32_t part);

/// A tree standing at (x, y, 0): a trunk and a crown of `facets` small irregular facets (as
/// foliage gives lidar returns that change from scan to scan). `index` picks its shape.
void add_tree(mesh::TriangleMesh& m, float x, float y, uint32_t index, uint32_t trunk,
              uint32_t foliage, uint32_t facets = 700);
/// A car parked with its length along y, its left side at x, its back at y0: body, cabin,
/// wheels; `index` picks its paint.
void add_car(mesh::TriangleMesh& m, float x, float y0, uint32_t index, uint32_t tyre);
/// An 8 m light pole at (x, y, 0), its arm and lamp reaching 1.7 m towards +x.
void add_light_pole(mesh::TriangleMesh& m, float x, float y, uint32_t metal);

/// Appends `piece` turned by `quarter_turns` x 90 degrees about the z axis (counter-clockwise
/// seen from above; exact, no rounding) and then moved by `offset_m`; its parts become new
/// parts. Makes a car along x of one along y, a light pole facing any street.
void append_placed(mesh::TriangleMesh& into, const mesh::TriangleMesh& piece, int quarter_turns,
                   const V& offset_m);

}  // namespace featsense::slam::scene_parts
