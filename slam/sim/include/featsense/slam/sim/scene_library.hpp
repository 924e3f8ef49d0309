#pragma once
/// The built-in scenes of `featsense simulate`, generated in code (deterministic: the same
/// mesh on every run and machine), with the named sensor paths through each.

#include <Eigen/Core>

#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::slam {

/// Names of the built-in scenes: "corridor", "lab", "parking".
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

/// Names of the paths of a built-in scene: "walk", "drive", "drone".
std::vector<std::string> path_names();
/// A named path through a built-in scene; throws std::invalid_argument when either name is
/// unknown.
NamedPath scene_path(const std::string& scene, const std::string& path);

}  // namespace featsense::slam
