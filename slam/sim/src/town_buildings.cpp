#include "town_buildings.hpp"

#include <algorithm>

#include "scene_parts.hpp"

namespace featsense::slam::town {
namespace {

using scene_parts::draw;
using scene_parts::Materials;
using scene_parts::V;

/// One side of a building in its own coordinates: u along the wall from `origin`, z up from
/// the building's floor, d out of the wall. Sides are axis-aligned, so boxes stay so.
struct Facade {
  V origin;
  V along;
  V out;
  float length_m;

  V at(float u, float z, float d) const { return origin + along * u + out * d + V(0, 0, z); }
  void box(mesh::TriangleMesh& m, float u0, float u1, float z0, float z1, float d0, float d1,
           uint32_t part) const {
    const V a = at(u0, z0, d0);
    const V b = at(u1, z1, d1);
    m.add_box(a.cwiseMin(b), a.cwiseMax(b), part);
  }
  /// A pane parallel to the wall, `d` in front of it.
  void pane(mesh::TriangleMesh& m, float u0, float u1, float z0, float z1, float d,
            uint32_t part) const {
    m.add_quad(at(u0, z0, d), at(u1, z0, d), at(u1, z1, d), at(u0, z1, d), part);
  }
};

float building_height_m(const FacadeStyle& style) {
  constexpr float kParapetM = 0.6f;
  return static_cast<float>(style.storeys) * style.storey_m + kParapetM;
}

void add_window(mesh::TriangleMesh& m, const BuildingParts& parts, const Facade& f, float centre,
                float half_width, float floor_z, const FacadeStyle& style) {
  const float bottom = floor_z + 0.9f;
  // The pane a little proud of the wall (glass mostly drops out), a sill under it.
  f.pane(m, centre - half_width, centre + half_width, bottom, bottom + style.window_height_m, 0.03f,
         parts.glass);
  f.box(m, centre - half_width - 0.1f, centre + half_width + 0.1f, bottom - 0.08f, bottom, 0.0f,
        0.18f, parts.trim);
}

void decorate(mesh::TriangleMesh& m, const BuildingParts& parts, const Facade& f,
              const FacadeStyle& style, bool level_ground) {
  const float height = building_height_m(style);
  const int bays = std::max(1, static_cast<int>((f.length_m - 1.0f) / style.bay_m));
  const float margin = 0.5f * (f.length_m - static_cast<float>(bays) * style.bay_m);
  const float half_window = 0.5f * style.bay_m * style.window_width_fraction;
  for (int b = 0; b < bays; ++b) {
    const float u0 = margin + static_cast<float>(b) * style.bay_m;
    const float centre = u0 + 0.5f * style.bay_m;
    for (int storey = 0; storey < style.storeys; ++storey) {
      const float z = static_cast<float>(storey) * style.storey_m;
      if (storey == 0 && level_ground && b == style.door_bay % bays) {
        f.box(m, centre - 0.6f, centre + 0.6f, 0.0f, 2.3f, 0.0f, 0.08f, parts.door);
        f.box(m, centre - 1.0f, centre + 1.0f, 2.5f, 2.65f, 0.0f, 1.0f, parts.trim);  // canopy
        continue;
      }
      if (storey == 0 && level_ground && style.shop_front) {
        f.pane(m, u0 + 0.25f, u0 + style.bay_m - 0.25f, 0.4f, style.storey_m - 0.4f, 0.03f,
               parts.glass);
        continue;
      }
      add_window(m, parts, f, centre, half_window, z, style);
      if (style.balconies && storey >= 1 && b % 2 == 0) {
        f.box(m, u0 + 0.3f, u0 + style.bay_m - 0.3f, z - 0.15f, z, 0.0f, 1.2f, parts.trim);
        f.box(m, u0 + 0.3f, u0 + style.bay_m - 0.3f, z, z + 1.0f, 1.15f, 1.2f, parts.trim);
      }
    }
  }
  if (style.pilasters) {
    for (int b = 0; b <= bays; ++b) {
      const float u = margin + static_cast<float>(b) * style.bay_m;
      f.box(m, u - 0.2f, u + 0.2f, 0.0f, height, 0.0f, 0.3f, parts.trim);
    }
  }
  if (style.cornice) f.box(m, 0.0f, f.length_m, height - 0.45f, height, 0.0f, 0.4f, parts.trim);
}

}  // namespace

BuildingParts add_building_parts(mesh::TriangleMesh& m, float wall_reflectance) {
  BuildingParts parts;
  parts.wall = m.add_part("facade", wall_reflectance);
  parts.trim = m.add_part("trim", Materials::kConcrete);
  parts.glass = m.add_part("window", Materials::kGlass);
  parts.door = m.add_part("door", Materials::kWood);
  return parts;
}

FacadeStyle draw_facade_style(uint32_t design, uint32_t building) {
  const auto pick = [&](uint32_t what, float lo, float hi) {
    return draw(100 + what, design, building, lo, hi);
  };
  FacadeStyle style;
  style.storey_m = pick(0, 3.0f, 3.6f);
  style.bay_m = pick(1, 3.0f, 4.6f);
  style.window_width_fraction = pick(2, 0.4f, 0.65f);
  style.window_height_m = pick(3, 1.3f, style.storey_m - 1.3f);
  style.pilasters = pick(4, 0, 1) < 0.5f;
  style.balconies = pick(5, 0, 1) < 0.3f;
  style.cornice = pick(6, 0, 1) < 0.6f;
  style.shop_front = pick(7, 0, 1) < 0.4f;
  style.door_bay = static_cast<int>(pick(8, 0, 4));
  style.storeys = 2 + static_cast<int>(pick(9, 0, 5));
  return style;
}

void add_building(mesh::TriangleMesh& m, const BuildingParts& parts, float x0, float y0, float x1,
                  float y1, float ground_x0_m, float ground_x1_m, const FacadeStyle& style,
                  unsigned street_sides) {
  const float low = std::min(ground_x0_m, ground_x1_m);
  const float floor_z = std::max(ground_x0_m, ground_x1_m);
  const bool level = floor_z - low < 0.05f;
  if (!level) m.add_box(V(x0, y0, low), V(x1, y1, floor_z), parts.trim);  // the stepped base
  m.add_box(V(x0, y0, floor_z), V(x1, y1, floor_z + building_height_m(style)), parts.wall);
  const float dx = x1 - x0;
  const float dy = y1 - y0;
  const Facade sides[4] = {
      {V(x0, y0, floor_z), V(1, 0, 0), V(0, -1, 0), dx},   // south
      {V(x1, y0, floor_z), V(0, 1, 0), V(1, 0, 0), dy},    // east
      {V(x1, y1, floor_z), V(-1, 0, 0), V(0, 1, 0), dx},   // north
      {V(x0, y1, floor_z), V(0, -1, 0), V(-1, 0, 0), dy},  // west
  };
  const unsigned masks[4] = {kSouth, kEast, kNorth, kWest};
  for (int s = 0; s < 4; ++s) {
    if (street_sides & masks[s]) decorate(m, parts, sides[s], style, level);
  }
}

void add_slab(mesh::TriangleMesh& m, float x0, float y0, float x1, float y1, float ground_x0_m,
              float ground_x1_m, float thickness_m, uint32_t part) {
  const float g0 = ground_x0_m;
  const float g1 = ground_x1_m;
  const float t = thickness_m;
  m.add_quad(V(x0, y0, g0 + t), V(x1, y0, g1 + t), V(x1, y1, g1 + t), V(x0, y1, g0 + t), part);
  m.add_quad(V(x0, y0, g0), V(x1, y0, g1), V(x1, y0, g1 + t), V(x0, y0, g0 + t), part);
  m.add_quad(V(x1, y1, g1), V(x0, y1, g0), V(x0, y1, g0 + t), V(x1, y1, g1 + t), part);
  m.add_quad(V(x0, y1, g0), V(x0, y0, g0), V(x0, y0, g0 + t), V(x0, y1, g0 + t), part);
  m.add_quad(V(x1, y0, g1), V(x1, y1, g1), V(x1, y1, g1 + t), V(x1, y0, g1 + t), part);
}

}  // namespace featsense::slam::town
