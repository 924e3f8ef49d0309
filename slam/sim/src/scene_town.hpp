#pragma once
/// The built-in `town` scene and its paths; private to slam/sim (scene_library.hpp is the way
/// in). The layout both the mesh and the paths are made from lives here.

#include <algorithm>
#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/sim/scene_library.hpp"

namespace featsense::slam::town {

// Streets run along x and y on a 50 m grid: street centre lines at x = 0, 50, ..., 200 and
// y = 0, 50, 100, 150; block (i, j), i in 0..3, j in 0..2, lies between x = 50 i and
// 50 (i + 1), y = 50 j and 50 (j + 1). Outer rows of buildings close the grid on all sides.
constexpr float kPitchM = 50.0f;
constexpr int kBlockColumns = 4;
constexpr int kBlockRows = 3;
constexpr float kHalfRoadM = 6.0f;  ///< kerb to street centre line: 12 m carriageways
constexpr float kSidewalkM = 2.5f;  ///< kerb to the facade line (before setbacks)
constexpr float kKerbHeightM = 0.15f;

// The east side is up a rise: the ground climbs kRiseM over the lots of the last column of
// blocks (x from 156 to 194 m), so the streets across them climb and the blocks there stand
// on sloping ground with stepped bases; the street at x = 200 and what lies east of it are up.
constexpr float kSlopeStartXM = 3 * kPitchM + kHalfRoadM;
constexpr float kSlopeEndXM = 4 * kPitchM - kHalfRoadM;
constexpr float kRiseM = 3.0f;

/// Height of the road surface at x (metres, map frame).
inline float ground_height_m(float x) {
  const float f = (x - kSlopeStartXM) / (kSlopeEndXM - kSlopeStartXM);
  return kRiseM * std::clamp(f, 0.0f, 1.0f);
}

/// Blocks (0, 1) and (2, 1) are the same block, 100 m apart along x: the same buildings,
/// trees, light poles and parked cars around them (perceptual aliasing, on purpose).
constexpr int kTwinI[2] = {0, 2};
constexpr int kTwinJ = 1;

/// Which day's parked cars: those of the day the town is mapped, or another day's: each bay
/// drawn anew (taken or empty), a car in it another model, parked up to 0.5 m further along.
enum class ParkedCars { kMappingDay, kAnotherDay };

/// The grid of blocks: the town's 4 x 3, or a larger one (the `city`: the town's streets and
/// rise, more blocks east and north, each of its own design but the twins).
struct TownLayout {
  int columns = kBlockColumns;
  int rows = kBlockRows;
};
inline constexpr TownLayout kCityLayout{12, 8};

/// The mesh (map frame, metres, Z up; roads at z = 0 west of the rise).
mesh::TriangleMesh build_town(ParkedCars cars = ParkedCars::kMappingDay, TownLayout layout = {});
/// "loop", "drive", "walk".
std::vector<std::string> town_path_names();
/// The named path, or one without waypoints when `name` is none of town_path_names().
NamedPath town_path(const std::string& name);
/// "tour": about 5 km through the city.
std::vector<std::string> city_path_names();
/// The named path, or one without waypoints when `name` is none of city_path_names().
NamedPath city_path(const std::string& name);

}  // namespace featsense::slam::town
