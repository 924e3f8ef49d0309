#include "featsense/slam/sim/scene_library.hpp"

#include <cmath>
#include <stdexcept>

#include "scene_parts.hpp"
#include "scene_town.hpp"
#include "street_route.hpp"

namespace featsense::slam {
namespace {

using scene_parts::add_car;
using scene_parts::add_light_pole;
using scene_parts::add_shelving;
using scene_parts::add_table;
using scene_parts::add_tree;
using scene_parts::add_wall_x;
using scene_parts::add_wall_y;
using scene_parts::draw;
using scene_parts::Materials;
using scene_parts::V;

/// 20 x 20 x 4 m room (x, y in [-10, 10]) with pillars, tables, shelving, a closed door in
/// the west wall and an open door (1.2 x 2.2 m) in the east wall to a 2 m wide corridor.
mesh::TriangleMesh lab() {
  mesh::TriangleMesh m;
  const uint32_t wall = m.add_part("wall", Materials::kPlaster);
  const uint32_t floor = m.add_part("floor", Materials::kFloorTiles);
  const uint32_t ceiling = m.add_part("ceiling", Materials::kPlaster);
  const uint32_t concrete = m.add_part("pillar", Materials::kConcrete);
  const uint32_t wood = m.add_part("table", Materials::kWood);
  const uint32_t metal = m.add_part("shelving", Materials::kMetal);
  m.add_quad(V(-10, -10, 0), V(30, -10, 0), V(30, 10, 0), V(-10, 10, 0), floor);
  m.add_quad(V(-10, -10, 4), V(-10, 10, 4), V(10, 10, 4), V(10, -10, 4), ceiling);
  add_wall_y(m, -10, -10, 10, 0, 4, wall);
  add_wall_y(m, 10, -10, 10, 0, 4, wall);
  add_wall_x(m, -10, -10, 10, 0, 4, wall);
  // East wall around the door opening at y in [-0.6, 0.6], z < 2.2.
  add_wall_x(m, 10, -10, -0.6f, 0, 4, wall);
  add_wall_x(m, 10, 0.6f, 10, 0, 4, wall);
  add_wall_x(m, 10, -0.6f, 0.6f, 2.2f, 4, wall);
  // A closed door in the west wall, a few centimetres proud of it.
  m.add_box(V(-10, 3, 0), V(-9.95f, 4, 2.1f), wood);
  // Corridor: x in [10, 30], y in [-1, 1], 3 m high, closed at its end; the room's floor
  // quad runs on under it.
  m.add_quad(V(10, -1, 3), V(10, 1, 3), V(30, 1, 3), V(30, -1, 3), ceiling);
  add_wall_y(m, -1, 10, 30, 0, 3, wall);
  add_wall_y(m, 1, 10, 30, 0, 3, wall);
  add_wall_x(m, 30, -1, 1, 0, 3, wall);
  for (float x : {-5.0f, 5.0f}) {
    for (float y : {-5.0f, 5.0f})
      m.add_box(V(x - 0.3f, y - 0.3f, 0), V(x + 0.3f, y + 0.3f, 4), concrete);
  }
  add_table(m, -3.0f, 2.0f, -1.2f, 3.0f, wood);
  add_table(m, 1.2f, -3.0f, 3.0f, -2.0f, wood);
  add_table(m, -1.0f, 4.0f, 1.0f, 5.0f, wood);
  add_table(m, 2.0f, 2.5f, 3.6f, 3.4f, wood);
  add_shelving(m, -8.0f, -5.5f, 9.0f, 0.6f, metal);
  add_shelving(m, -2.0f, 0.5f, 9.0f, 0.6f, metal);
  add_shelving(m, 3.0f, 5.5f, 9.0f, 0.6f, metal);
  return m;
}

/// A 60 m long, 2.5 m wide, 2.8 m high hallway, closed at both ends: plain walls only.
mesh::TriangleMesh corridor() {
  mesh::TriangleMesh m;
  const uint32_t wall = m.add_part("wall", Materials::kPlaster);
  const uint32_t floor = m.add_part("floor", Materials::kFloorTiles);
  m.add_quad(V(0, -1.25f, 0), V(60, -1.25f, 0), V(60, 1.25f, 0), V(0, 1.25f, 0), floor);
  m.add_quad(V(0, -1.25f, 2.8f), V(0, 1.25f, 2.8f), V(60, 1.25f, 2.8f), V(60, -1.25f, 2.8f), wall);
  add_wall_y(m, -1.25f, 0, 60, 0, 2.8f, wall);
  add_wall_y(m, 1.25f, 0, 60, 0, 2.8f, wall);
  add_wall_x(m, 0, -1.25f, 1.25f, 0, 2.8f, wall);
  add_wall_x(m, 60, -1.25f, 1.25f, 0, 2.8f, wall);
  return m;
}

/// A 90 x 30 m lot (x in [0, 90], y in [0, 30]): three rows of cars, kerbs, light poles,
/// trees, a ramp up to a deck, and building facades to the north and east.
mesh::TriangleMesh parking() {
  mesh::TriangleMesh m;
  const uint32_t asphalt = m.add_part("asphalt", Materials::kAsphalt);
  const uint32_t concrete = m.add_part("kerb", Materials::kConcrete);
  const uint32_t facade = m.add_part("facade", Materials::kConcrete);
  const uint32_t glass = m.add_part("window", Materials::kGlass);
  const uint32_t metal = m.add_part("light pole", Materials::kMetal);
  const uint32_t trunk = m.add_part("tree trunk", Materials::kBark);
  const uint32_t foliage = m.add_part("foliage", Materials::kFoliage);
  const uint32_t tyre = m.add_part("tyre", Materials::kTyre);
  m.add_quad(V(0, 0, 0), V(96, 0, 0), V(96, 36, 0), V(0, 36, 0), asphalt);
  // Facades: north (y = 30) and east (x = 90) buildings, 12 m high, with window bays.
  m.add_box(V(0, 30, 0), V(96, 36, 12), facade);
  m.add_box(V(90, 0, 0), V(96, 30, 12), facade);
  for (int k = 0; k < 22; ++k) {
    const float x = 2.0f + 4.0f * static_cast<float>(k);
    for (float z : {1.0f, 4.5f, 8.0f})
      m.add_box(V(x, 29.9f, z), V(x + 2.2f, 30.0f, z + 2.0f), glass);
    m.add_box(V(x + 2.6f, 29.6f, 0), V(x + 3.0f, 30.0f, 12), facade);  // pilasters
  }
  for (int k = 0; k < 7; ++k) {
    const float y = 1.5f + 4.0f * static_cast<float>(k);
    m.add_box(V(89.9f, y, 4.5f), V(90.0f, y + 2.2f, 6.5f), glass);
  }
  // Kerbs: the sidewalk edge (y = 2), the median between rows B and C.
  m.add_box(V(0, 0, 0), V(60, 2, 0.15f), concrete);
  m.add_box(V(0, 18.5f, 0), V(60, 20, 0.15f), concrete);
  // Cars: row A (y 3..7.5), row B (y 14..18.5), row C (y 20..24.5); a few empty bays.
  const float rows[3] = {3.0f, 14.0f, 20.0f};
  uint32_t car = 0;
  for (uint32_t r = 0; r < 3; ++r) {
    for (uint32_t bay = 0; bay < 22; ++bay) {
      if (draw(8, r, bay, 0, 1) < 0.2f) continue;
      add_car(m, 1.0f + 2.6f * static_cast<float>(bay), rows[r] + draw(9, r, bay, -0.2f, 0.2f),
              car++, tyre);
    }
  }
  // Trees on the sidewalk and the median, light poles between them.
  uint32_t tree = 0;
  for (int k = 0; k < 6; ++k) {
    add_tree(m, 5.0f + 10.0f * static_cast<float>(k), 1.0f, tree++, trunk, foliage);
    add_tree(m, 5.0f + 10.0f * static_cast<float>(k), 19.25f, tree++, trunk, foliage);
  }
  for (int k = 0; k < 3; ++k) {
    add_light_pole(m, 10.0f + 20.0f * static_cast<float>(k), 1.2f, metal);
    add_light_pole(m, 10.0f + 20.0f * static_cast<float>(k), 19.25f, metal);
  }
  // Ramp from x = 64 (ground) to x = 80 (2.5 m) beside a deck up to the east building.
  const uint32_t ramp = m.add_part("ramp", Materials::kConcrete);
  m.add_quad(V(64, 0.5f, 0), V(80, 0.5f, 2.5f), V(80, 7.5f, 2.5f), V(64, 7.5f, 0), ramp);
  m.add_quad(V(64, 0.5f, 0), V(80, 0.5f, 0), V(80, 0.5f, 2.5f), V(64, 0.5f, 0.01f), concrete);
  m.add_quad(V(64, 7.5f, 0), V(64, 7.5f, 0.01f), V(80, 7.5f, 2.5f), V(80, 7.5f, 0), concrete);
  m.add_box(V(80, 0.5f, 0), V(90, 7.5f, 2.5f), concrete);
  m.add_box(V(64, 7.5f, 2.5f), V(90, 7.7f, 3.5f), concrete);  // parapet
  return m;
}

std::string listed(const std::vector<std::string>& names) {
  std::string list;
  for (size_t i = 0; i < names.size(); ++i) list += (i ? ", " : "") + names[i];
  return list;
}

std::string unknown_scene(const std::string& name) {
  return "unknown scene '" + name + "' (built-in: " + listed(scene_names()) + ")";
}

std::vector<Eigen::Vector3d> at_height(const std::vector<Eigen::Vector2d>& xy, double z) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : xy) out.emplace_back(p.x(), p.y(), z);
  return out;
}

/// Twice round the open east end of the lot, then back west along the north lane: about
/// 240 m at 5 m/s, each lap's 70 m driven again 70 m later in the same direction.
std::vector<Eigen::Vector3d> parking_loop() {
  using P = Eigen::Vector2d;
  RouteShape shape;
  shape.turn_radius_m = 5.0;
  const std::vector<P> corners = {P(5, 10.75),  P(85, 10.75), P(85, 27.25), P(64, 27.25),
                                  P(64, 10.75), P(85, 10.75), P(85, 27.25), P(5, 27.25)};
  return at_height(street_route(corners, shape), 1.9);
}

}  // namespace

std::vector<std::string> scene_names() {
  return {"city", "corridor", "lab", "parking", "town", "town-changed"};
}

bool is_builtin_scene(const std::string& name) {
  for (const std::string& s : scene_names()) {
    if (s == name) return true;
  }
  return false;
}

mesh::TriangleMesh build_scene(const std::string& name) {
  if (name == "lab") return lab();
  if (name == "parking") return parking();
  if (name == "corridor") return corridor();
  if (name == "town") return town::build_town();
  if (name == "town-changed") return town::build_town(town::ParkedCars::kAnotherDay);
  if (name == "city") return town::build_town(town::ParkedCars::kMappingDay, town::kCityLayout);
  throw std::invalid_argument(unknown_scene(name));
}

std::vector<std::string> path_names(const std::string& scene) {
  if (!is_builtin_scene(scene)) throw std::invalid_argument(unknown_scene(scene));
  if (scene == "town" || scene == "town-changed") return town::town_path_names();
  if (scene == "city") return town::city_path_names();
  if (scene == "parking") return {"walk", "drive", "drone", "loop"};
  return {"walk", "drive", "drone"};
}

NamedPath scene_path(const std::string& scene, const std::string& path) {
  using P = Eigen::Vector2d;
  using W = Eigen::Vector3d;
  if (!is_builtin_scene(scene)) throw std::invalid_argument(unknown_scene(scene));
  NamedPath out;
  out.name = path;
  if (scene == "town" || scene == "town-changed") {
    out = town::town_path(path);
  } else if (scene == "city") {
    out = town::city_path(path);
  } else if (scene == "lab") {
    if (path == "walk") {
      out.waypoints_m = at_height({P(-7.5, -7.5), P(0, -7.5), P(7.5, -7), P(7.5, 0), P(7, 7.5),
                                   P(0, 7.5), P(-7.5, 7), P(-7.5, 0), P(-3, -4.5)},
                                  1.7);
      out.speed_mps = 1.4;
    } else if (path == "drive") {
      // Round the room, then straight through the east door into the corridor.
      out.waypoints_m = at_height(
          {P(-7.5, -7.5), P(0, -7.5), P(6, -6), P(7, -2), P(8.5, 0), P(10, 0), P(12, 0), P(27, 0)},
          0.5);
      out.speed_mps = 1.2;
    } else if (path == "drone") {
      out.waypoints_m = {W(-7, -7, 1.5), W(0, -6, 3), W(6, -7, 2), W(7, 0, 3.2),  W(6, 7, 1.5),
                         W(0, 6.5, 3),   W(-7, 7, 2), W(-7, 0, 3), W(-3, -3.5, 2)};
      out.speed_mps = 3.0;
      out.tilt = true;
    }
  } else if (scene == "corridor") {
    if (path == "walk") {
      out.waypoints_m = at_height({P(2, 0), P(20, 0.2), P(40, -0.2), P(58, 0)}, 1.5);
      out.speed_mps = 1.4;
    } else if (path == "drive") {
      out.waypoints_m = at_height({P(2, 0), P(30, 0), P(58, 0)}, 0.5);
      out.speed_mps = 2.0;
    } else if (path == "drone") {
      out.waypoints_m = {W(2, 0, 1.2),    W(12, 0.6, 2.2),  W(22, -0.6, 1.0),
                         W(32, 0.6, 2.2), W(42, -0.6, 1.2), W(58, 0, 1.8)};
      out.speed_mps = 4.0;
      out.tilt = true;
    }
  } else {  // parking
    if (path == "walk") {
      out.waypoints_m = at_height({P(4, 11), P(20, 11.8), P(35, 10.5), P(50, 11.2), P(63, 14),
                                   P(64, 24), P(50, 27), P(30, 27.5)},
                                  1.7);
      out.speed_mps = 1.4;
    } else if (path == "drive") {
      out.waypoints_m = at_height({P(2, 10.75), P(30, 10.75), P(55, 10.75), P(68, 12), P(72, 19),
                                   P(68, 26), P(55, 27.25), P(5, 27.25)},
                                  1.9);
      out.speed_mps = 5.0;
    } else if (path == "drone") {
      out.waypoints_m = {W(5, 11, 3),  W(20, 9, 4),    W(30, 13, 2.5), W(40, 9, 5),
                         W(50, 13, 3), W(62, 11, 4),   W(70, 20, 6),   W(62, 27, 3),
                         W(45, 26, 5), W(30, 28, 2.5), W(15, 26, 4),   W(5, 27, 3)};
      out.speed_mps = 6.0;
      out.tilt = true;
    } else if (path == "loop") {
      out.waypoints_m = parking_loop();
      out.speed_mps = 5.0;
    }
  }
  if (out.waypoints_m.empty())
    throw std::invalid_argument("unknown path '" + path + "' of the " + scene +
                                " scene (its paths: " + listed(path_names(scene)) + ")");
  return out;
}

}  // namespace featsense::slam
