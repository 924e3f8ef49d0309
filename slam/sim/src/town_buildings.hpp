#pragma once
/// Town buildings: boxes with the facade structure a LiDAR sees (window bays with sills,
/// pilasters, balconies, cornices, doors with canopies, shop fronts), and sloping ground
/// pieces (sidewalk slabs, stepped bases); private to slam/sim.

#include <cstdint>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::slam::town {

/// The parts (materials) a town mesh shares among its buildings.
struct BuildingParts {
  uint32_t wall = 0;
  uint32_t trim = 0;  ///< sills, pilasters, cornices, bases
  uint32_t glass = 0;
  uint32_t door = 0;
};
BuildingParts add_building_parts(mesh::TriangleMesh& m, float wall_reflectance);

/// How one building's facades look; drawn from (design, building) so that a block built
/// twice from the same design looks the same.
struct FacadeStyle {
  float storey_m = 3.2f;
  float bay_m = 3.6f;
  float window_width_fraction = 0.5f;
  float window_height_m = 1.6f;
  bool pilasters = false;
  bool balconies = false;
  bool cornice = false;
  bool shop_front = false;  ///< ground floor glazed across the bays but the door's
  int door_bay = 0;
  int storeys = 3;
};
FacadeStyle draw_facade_style(uint32_t design, uint32_t building);

/// Which sides of a footprint face a street and get facade structure.
enum Side : unsigned { kSouth = 1u, kEast = 2u, kNorth = 4u, kWest = 8u };

/// A building over the footprint (x0, y0)-(x1, y1) (metres) on ground that rises linearly
/// from `ground_x0_m` at x0 to `ground_x1_m` at x1: a base of concrete evens out the slope
/// (a stepped base), the building stands on it; facades with structure on `street_sides`.
/// Doors and shop fronts only where the ground is level.
void add_building(mesh::TriangleMesh& m, const BuildingParts& parts, float x0, float y0, float x1,
                  float y1, float ground_x0_m, float ground_x1_m, const FacadeStyle& style,
                  unsigned street_sides);

/// A slab `thickness_m` thick over the rectangle (x0, y0)-(x1, y1) on ground that rises
/// linearly from `ground_x0_m` at x0 to `ground_x1_m` at x1: top and four sides (a sidewalk
/// with its kerbs, a plinth).
void add_slab(mesh::TriangleMesh& m, float x0, float y0, float x1, float y1, float ground_x0_m,
              float ground_x1_m, float thickness_m, uint32_t part);

}  // namespace featsense::slam::town
