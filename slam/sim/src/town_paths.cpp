// The paths through `town`: `loop` comes back to places it passed several hundred metres
// before, in the same and in the opposite direction (loop closure's test ground); `drive`
// passes both twin blocks and never comes back (no loop may be found); `walk` is short.

#include "scene_town.hpp"
#include "street_route.hpp"

namespace featsense::slam::town {
namespace {

using P = Eigen::Vector2d;

/// Street crossings by grid index: (X, Y) is where the streets x = 50 X and y = 50 Y meet.
std::vector<P> crossings(const std::vector<P>& grid) {
  std::vector<P> out;
  for (const P& g : grid) out.push_back(static_cast<double>(kPitchM) * g);
  return out;
}

/// The route at `height_m` above the road (which climbs over the rise).
std::vector<Eigen::Vector3d> above_road(const std::vector<P>& xy, double height_m) {
  std::vector<Eigen::Vector3d> out;
  for (const P& p : xy) {
    out.emplace_back(p.x(), p.y(), ground_height_m(static_cast<float>(p.x())) + height_m);
  }
  return out;
}

constexpr double kCarSensorHeightM = 1.9;

/// Driving on the right, 1.25 m off the centre line: passes in opposite directions are
/// 2.5 m apart.
RouteShape car_lane() {
  RouteShape shape;
  shape.lane_offset_m = 1.25;
  shape.turn_radius_m = 7.0;
  return shape;
}

}  // namespace

std::vector<std::string> town_path_names() { return {"loop", "drive", "walk"}; }

NamedPath town_path(const std::string& name) {
  NamedPath out;
  out.name = name;
  if (name == "loop") {
    // About 1.05 km. Revisits, s along the path: Y=1 from X=1 to 2 eastbound at 50 and
    // 650 m, X=2 from Y=1 to 2 northbound at 100 and 700 m (same direction); Y=3 between
    // X=2 and 3 eastbound at 200 m and westbound at 850 m, Y=1 from X=0 to 1 eastbound at
    // the start and westbound at the end (opposite). Climbs and comes down the rise twice.
    const std::vector<P> grid = {P(0, 1), P(2, 1), P(2, 3), P(4, 3), P(4, 1), P(3, 1),
                                 P(3, 0), P(1, 0), P(1, 1), P(2, 1), P(2, 2), P(3, 2),
                                 P(3, 3), P(1, 3), P(1, 1), P(0, 1)};
    out.waypoints_m = above_road(street_route(crossings(grid), car_lane()), kCarSensorHeightM);
    out.speed_mps = 7.0;
  } else if (name == "drive") {
    // About 640 m past both twin blocks, each seen from its west and from its south side,
    // the second 40 s after the first; no street twice, no place within 50 m of an earlier
    // one but at the corners just turned.
    const std::vector<P> grid = {P(0, 2), P(0, 1), P(1, 1), P(1, 0),  P(4, 0),
                                 P(4, 1), P(2, 1), P(2, 3), P(0.1, 3)};
    out.waypoints_m = above_road(street_route(crossings(grid), car_lane()), kCarSensorHeightM);
    out.speed_mps = 7.0;
  } else if (name == "walk") {
    // Down the middle of two streets (a car-free morning), about 85 m.
    RouteShape middle;
    middle.turn_radius_m = 3.0;
    const std::vector<P> grid = {P(0.1, 2), P(1, 2), P(1, 2.8)};
    out.waypoints_m = above_road(street_route(crossings(grid), middle), 1.7);
    out.speed_mps = 1.4;
  }
  return out;
}

std::vector<std::string> city_path_names() { return {"tour"}; }

NamedPath city_path(const std::string& name) {
  NamedPath out;
  out.name = name;
  if (name == "tour") {
    // About 5 km through the 12 x 8 blocks of the city, new streets most of the way: west to
    // east and back along every second street y = 0, 100, ..., 400 (3.4 km), then revisits:
    // round a block and back along y = 400 (opposite direction), south across every one of
    // those streets on x = 300, north on x = 200 and south on x = 50 (crossing each twice
    // more). A prefix of it (--frames) is a shorter route through the same city.
    const std::vector<P> grid = {P(0, 0),  P(12, 0), P(12, 2), P(0, 2), P(0, 4),
                                 P(12, 4), P(12, 6), P(0, 6),  P(0, 8), P(12, 8),
                                 P(12, 7), P(11, 7), P(11, 8), P(6, 8), P(6, 0),
                                 P(4, 0),  P(4, 8),  P(1, 8),  P(1, 1)};
    out.waypoints_m = above_road(street_route(crossings(grid), car_lane()), kCarSensorHeightM);
    out.speed_mps = 7.0;
  }
  return out;
}

}  // namespace featsense::slam::town
