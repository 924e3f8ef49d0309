// The `town` scene: a 4 x 3 grid of blocks between 12 m streets, each block a few buildings
// with structured facades around a courtyard (or a small square), sidewalks with trees and
// light poles, cars parked along the kerbs; two blocks alike; the east side up a rise.

#include <cmath>

#include "scene_parts.hpp"
#include "scene_town.hpp"
#include "town_buildings.hpp"

namespace featsense::slam::town {
namespace {

using scene_parts::append_placed;
using scene_parts::draw;
using scene_parts::Materials;
using scene_parts::V;

constexpr float kLotLoM = kHalfRoadM;  ///< block-local lot (sidewalk) bounds
constexpr float kLotHiM = kPitchM - kHalfRoadM;
constexpr float kFrontLoM = kLotLoM + kSidewalkM;  ///< block-local facade lines
constexpr float kFrontHiM = kLotHiM - kSidewalkM;
constexpr uint32_t kTreeFacets = 220;  ///< a third of the parking's trees: a town has many

/// Ground height in a block's own frame (x from its west street's centre line).
struct BlockGround {
  float west_x_m;  ///< the block's offset in the map
  float at(float x_local) const { return ground_height_m(west_x_m + x_local); }
};

/// What a block is built from: blocks of one design are alike, wherever they stand.
uint32_t block_design(int i, int j, int columns) {
  if (j == kTwinJ && i == kTwinI[1]) return block_design(kTwinI[0], j, columns);
  return static_cast<uint32_t>(1 + i + columns * j);
}

float wall_reflectance(uint32_t design, uint32_t building) {
  static const float kWalls[] = {Materials::kPlaster, Materials::kBrick, Materials::kConcrete};
  return kWalls[static_cast<int>(draw(30, design, building, 0, 3)) % 3];
}

/// A small square instead of one of the four buildings: trees, a fountain, low planters.
void add_square(mesh::TriangleMesh& m, float x0, float y0, float x1, float y1, float ground,
                uint32_t design) {
  mesh::TriangleMesh piece;
  const uint32_t stone = piece.add_part("planter", Materials::kConcrete);
  const float cx = 0.5f * (x0 + x1);
  const float cy = 0.5f * (y0 + y1);
  piece.add_cylinder(V(cx, cy, 0), 1.6f, 0.6f, 16, stone);
  piece.add_box(V(x0 + 1, y0 + 1, 0), V(x0 + 4, y0 + 1.6f, 0.5f), stone);
  piece.add_box(V(x1 - 4, y1 - 1.6f, 0), V(x1 - 1, y1 - 1, 0.5f), stone);
  const uint32_t trunk = piece.add_part("tree trunk", Materials::kBark);
  const uint32_t foliage = piece.add_part("foliage", Materials::kFoliage);
  scene_parts::add_tree(piece, x0 + 3.5f, y1 - 3.5f, design * 64 + 60, trunk, foliage, kTreeFacets);
  scene_parts::add_tree(piece, x1 - 3.5f, y0 + 3.5f, design * 64 + 61, trunk, foliage, kTreeFacets);
  append_placed(m, piece, 0, V(0, 0, ground));
}

/// Four buildings around a courtyard (or three and a square), on the block's lot in its
/// own frame: facade lines set back by a few metres here and there, passages between.
void add_block_buildings(mesh::TriangleMesh& m, uint32_t design, const BlockGround& ground) {
  const float split_x = kFrontLoM + draw(20, design, 0, 14.0f, 19.0f);
  const float split_y = kFrontLoM + draw(20, design, 1, 14.0f, 19.0f);
  const float gap = draw(20, design, 2, 0, 1) < 0.5f ? 0.0f : draw(20, design, 3, 1.5f, 3.0f);
  const int square =
      draw(21, design, 0, 0, 1) < 0.3f ? static_cast<int>(draw(21, design, 1, 0, 4)) : -1;
  const auto setback = [&](uint32_t building, uint32_t side) {
    return draw(22, design, 4 * building + side, 0, 1) < 0.6f
               ? 0.0f
               : draw(23, design, 4 * building + side, 0.8f, 3.0f);
  };
  for (uint32_t b = 0; b < 4; ++b) {
    const bool east = b % 2 == 1;
    const bool north = b >= 2;
    const float x0 = east ? split_x + 0.5f * gap : kFrontLoM + setback(b, 3);
    const float x1 = east ? kFrontHiM - setback(b, 1) : split_x - 0.5f * gap;
    const float y0 = north ? split_y + 0.5f * gap : kFrontLoM + setback(b, 0);
    const float y1 = north ? kFrontHiM - setback(b, 2) : split_y - 0.5f * gap;
    const float lot_top_x0 = ground.at(x0) + kKerbHeightM;
    const float lot_top_x1 = ground.at(x1) + kKerbHeightM;
    if (static_cast<int>(b) == square) {
      add_square(m, x0, y0, x1, y1, lot_top_x0, design);
      continue;
    }
    const unsigned sides = (east ? kEast : kWest) | (north ? kNorth : kSouth);
    const BuildingParts parts = add_building_parts(m, wall_reflectance(design, b));
    add_building(m, parts, x0, y0, x1, y1, lot_top_x0, lot_top_x1, draw_facade_style(design, b),
                 sides);
  }
}

/// Along one side of a block: trees and a light pole on the sidewalk, cars parked at the
/// kerb (not on sloping streets). `side` 0..3 is south, east, north, west.
void add_block_side(mesh::TriangleMesh& m, uint32_t design, uint32_t side,
                    const BlockGround& ground, ParkedCars cars) {
  // A point `along` the side (from its west or south end) `from_kerb` metres into the lot
  // (negative: out into the street), in the block's frame, at the ground's height.
  const auto spot = [&](float along, float from_kerb) {
    const float a = kLotLoM + along;
    V p;
    switch (side) {
      case 0:
        p = V(a, kLotLoM + from_kerb, 0);
        break;
      case 1:
        p = V(kLotHiM - from_kerb, a, 0);
        break;
      case 2:
        p = V(a, kLotHiM - from_kerb, 0);
        break;
      default:
        p = V(kLotLoM + from_kerb, a, 0);
        break;
    }
    p.z() = ground.at(p.x());
    return p;
  };
  const V on_sidewalk(0, 0, kKerbHeightM);
  if (draw(24, design, side, 0, 1) < 0.6f) {
    for (uint32_t k = 0; k < 3; ++k) {
      mesh::TriangleMesh tree;
      const uint32_t trunk = tree.add_part("tree trunk", Materials::kBark);
      const uint32_t foliage = tree.add_part("foliage", Materials::kFoliage);
      scene_parts::add_tree(tree, 0, 0, design * 64 + side * 8 + k, trunk, foliage, kTreeFacets);
      append_placed(m, tree, 0, spot(7.0f + 12.0f * static_cast<float>(k), 1.0f) + on_sidewalk);
    }
  }
  // A light pole halfway between two trees, its arm over the street.
  mesh::TriangleMesh pole;
  scene_parts::add_light_pole(pole, 0, 0, pole.add_part("light pole", Materials::kMetal));
  const int arm_to_street = static_cast<int>(side + 3) % 4;  // quarter turns from +x
  const float pole_along = draw(25, design, side, 0, 1) < 0.5f ? 13.0f : 25.0f;
  append_placed(m, pole, arm_to_street, spot(pole_along, 0.5f) + on_sidewalk);
  const bool sloping_street = side % 2 == 0 && ground.at(kLotLoM) != ground.at(kLotHiM);
  if (sloping_street) return;
  // Five bays from 5 m after the lot's corner to 6.5 m before the next: corners stay clear.
  // Another day's cars come from streams of their own: as many bays taken, other ones.
  const bool another_day = cars == ParkedCars::kAnotherDay;
  for (uint32_t k = 0; k < 5; ++k) {
    if (draw(another_day ? 27 : 26, design, side * 8 + k, 0, 1) < 0.4f) continue;
    mesh::TriangleMesh car;
    const uint32_t model = design * 64 + side * 8 + k + (another_day ? 4096u : 0u);
    scene_parts::add_car(car, 0, 0, model, car.add_part("tyre", Materials::kTyre));
    // The car is 1.8 x 4.5 m from (0, 0) with its length along y; along a street that runs
    // along x it is turned a quarter. Its body goes 0.3 to 2.1 m out from the kerb. The bays
    // are 5.5 m apart: half a metre either way keeps neighbours apart.
    const float shift = another_day ? draw(28, design, side * 8 + k, -0.5f, 0.5f) : 0.0f;
    const float along = 5.0f + 5.5f * static_cast<float>(k) + shift;
    const V a = spot(along, -0.3f);
    const V b = spot(along + 4.5f, -2.1f);
    const bool along_x = side % 2 == 0;
    const V turned_lo = along_x ? V(-4.5f, 0, 0) : V(0, 0, 0);
    append_placed(m, car, along_x ? 1 : 0, a.cwiseMin(b) - turned_lo);
  }
}

mesh::TriangleMesh block(uint32_t design, const BlockGround& ground, ParkedCars cars) {
  mesh::TriangleMesh m;
  const uint32_t kerb = m.add_part("sidewalk", Materials::kConcrete);
  add_slab(m, kLotLoM, kLotLoM, kLotHiM, kLotHiM, ground.at(kLotLoM), ground.at(kLotHiM),
           kKerbHeightM, kerb);
  add_block_buildings(m, design, ground);
  for (uint32_t side = 0; side < 4; ++side) add_block_side(m, design, side, ground, cars);
  return m;
}

/// Calls fn(x0, x1) for the pieces of [x0, x1] on which the ground is planar.
template <typename Fn>
void for_each_planar_piece(float x0, float x1, Fn fn) {
  const float cuts[4] = {x0, std::clamp(kSlopeStartXM, x0, x1), std::clamp(kSlopeEndXM, x0, x1),
                         x1};
  for (int k = 0; k < 3; ++k) {
    if (cuts[k + 1] > cuts[k]) fn(cuts[k], cuts[k + 1]);
  }
}

/// The rows of buildings beyond the outer streets, their facades facing the town, on a
/// sidewalk that runs under them. `row` 0..3: south, east, north, west.
void add_outer_row(mesh::TriangleMesh& m, uint32_t row, float lo_m, float hi_m,
                   const TownLayout& layout) {
  constexpr float kDepthM = 9.5f;
  const uint32_t kerb = m.add_part("sidewalk", Materials::kConcrete);
  const float near = kHalfRoadM;  // kerb, from the outer street's centre line
  const float front = kHalfRoadM + kSidewalkM;
  const float town_x = static_cast<float>(layout.columns) * kPitchM;
  const float town_y = static_cast<float>(layout.rows) * kPitchM;
  // The strip across the row: [a0, a1] away from the town's edge street.
  const auto footprint = [&](float s0, float s1, float a0, float a1, float* x0, float* y0,
                             float* x1, float* y1) {
    switch (row) {
      case 0:
        *x0 = s0, *x1 = s1, *y0 = -a1, *y1 = -a0;
        break;
      case 1:
        *x0 = town_x + a0, *x1 = town_x + a1, *y0 = s0, *y1 = s1;
        break;
      case 2:
        *x0 = s0, *x1 = s1, *y0 = town_y + a0, *y1 = town_y + a1;
        break;
      default:
        *x0 = -a1, *x1 = -a0, *y0 = s0, *y1 = s1;
        break;
    }
  };
  float x0, y0, x1, y1;
  footprint(lo_m, hi_m, near, front + kDepthM + 1.0f, &x0, &y0, &x1, &y1);
  for_each_planar_piece(x0, x1, [&](float a, float b) {
    add_slab(m, a, y0, b, y1, ground_height_m(a), ground_height_m(b), kKerbHeightM, kerb);
  });
  const unsigned facing_town[4] = {kNorth, kWest, kSouth, kEast};
  uint32_t k = 0;
  for (float s = lo_m; s < hi_m - 1.0f; ++k) {
    const uint32_t design = 1000 + 100 * row + k;
    const float width = std::min(draw(27, design, 0, 16.0f, 28.0f), hi_m - s);
    const float setback = draw(28, design, 0, 0, 1) < 0.6f ? 0.0f : draw(28, design, 1, 0.8f, 2.5f);
    footprint(s, s + width, front + setback, front + kDepthM, &x0, &y0, &x1, &y1);
    const BuildingParts parts = add_building_parts(m, wall_reflectance(design, 0));
    add_building(m, parts, x0, y0, x1, y1, ground_height_m(x0) + kKerbHeightM,
                 ground_height_m(x1) + kKerbHeightM, draw_facade_style(design, 0),
                 facing_town[row]);
    s += width;
  }
}

}  // namespace

mesh::TriangleMesh build_town(ParkedCars cars, TownLayout layout) {
  mesh::TriangleMesh m;
  const float town_x = static_cast<float>(layout.columns) * kPitchM;
  const float town_y = static_cast<float>(layout.rows) * kPitchM;
  const float edge = kHalfRoadM + kSidewalkM + 11.0f;  // beyond the outer rows
  const uint32_t asphalt = m.add_part("asphalt", Materials::kAsphalt);
  for_each_planar_piece(-edge, town_x + edge, [&](float a, float b) {
    const float za = ground_height_m(a);
    const float zb = ground_height_m(b);
    m.add_quad(V(a, -edge, za), V(b, -edge, zb), V(b, town_y + edge, zb), V(a, town_y + edge, za),
               asphalt);
  });
  // South and north rows run past the corners; east and west rows fit between them.
  add_outer_row(m, 0, -edge, town_x + edge, layout);
  add_outer_row(m, 2, -edge, town_x + edge, layout);
  add_outer_row(m, 1, -kHalfRoadM, town_y + kHalfRoadM, layout);
  add_outer_row(m, 3, -kHalfRoadM, town_y + kHalfRoadM, layout);
  for (int j = 0; j < layout.rows; ++j) {
    for (int i = 0; i < layout.columns; ++i) {
      const float x = kPitchM * static_cast<float>(i);
      const float y = kPitchM * static_cast<float>(j);
      append_placed(m, block(block_design(i, j, layout.columns), BlockGround{x}, cars), 0,
                    V(x, y, 0));
    }
  }
  return m;
}

}  // namespace featsense::slam::town
