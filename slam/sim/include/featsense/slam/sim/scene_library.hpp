#pragma once
/// The built-in scenes of `featsense simulate`, generated in code (deterministic: the same
/// mesh on every run and machine), with the named sensor paths through each.

#include <Eigen/Core>

#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::slam {

/// Names of the built-in scenes: "city", "corridor", "lab", "parking", "town". The town: a 4 x 3
/// grid of blocks (x in [0, 200], y in [0, 150] between the outer streets' centre lines, on
/// a 50 m grid, 12 m carriageways) closed by outer rows of buildings; the ground rises 3 m
/// between x = 156 and 194; blocks (0, 1) and (2, 1), with their lower-left street crossings
/// at (0, 50) and (100, 50), are alike (the same mesh moved 100 m along x). "town-changed":
/// the town on another day, its paths the town's: the cars parked along its kerbs moved
/// (each bay drawn anew, taken or empty; another model, up to 0.5 m further along), the rest
/// the same, for localizing in a map made of "town". "city": the town's streets, rise and
/// twin blocks in a 12 x 8 grid of blocks (x in [0, 600], y in [0, 400]), for routes of
/// kilometres (its path "tour": about 5 km).
std::vector<std::string> scene_names();
/// True when `name` is a built-in scene.
bool is_builtin_scene(const std::string& name);
/// The scene's mesh (map frame, metres, Z up, floor at z = 0). Throws std::invalid_argument
/// naming the scenes when `name` is unknown.
mesh::TriangleMesh build_scene(const std::string& name);

/// A sensor path: waypoints (map frame, metres) travelled at constant speed.
struct NamedPath {
  std::string name;
  std::vector<Eigen::Vector3d> waypoints_m;
  double speed_mps = 1.0;
  bool tilt = false;  ///< roll into turns and pitch with climbs, as a multirotor does
};

/// Names of the paths of a built-in scene: "walk", "drive", "drone" (lab, corridor), and
/// "loop" (parking); "loop", "drive", "walk" (town, town-changed); "tour" (city). Throws
/// std::invalid_argument naming the scenes when `scene` is unknown.
std::vector<std::string> path_names(const std::string& scene);
/// A named path through a built-in scene; throws std::invalid_argument when either name is
/// unknown (naming the scenes, or that scene's paths).
NamedPath scene_path(const std::string& scene, const std::string& path);

}  // namespace featsense::slam
