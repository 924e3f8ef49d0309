#pragma once
// A small output folder as `featsense map` leaves it, for the viewer's tests: a closed room
// (mesh.ply), its error layer (mesh_error.ply), a navigation cost (navmesh.ply), a path
// (trajectory.tum) and a plan view.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "featsense/viewer_export/mesh_writer.hpp"
#include "mesh/mesh_test_shapes.hpp"

namespace featsense::test {

/// A room of 4 m x 3 m x 2.5 m: walls, floor and ceiling of `n` x `n` cells each face.
inline mesh::TriangleMesh view_test_room(int n) {
  mesh::TriangleMesh room;
  const mesh::TriangleMesh face = grid_plane(0, 1, 0, 1, 0, n);
  // Each face: the unit square moved onto the room's side.
  const auto add_face = [&](const Eigen::Vector3f& origin, const Eigen::Vector3f& u,
                            const Eigen::Vector3f& v) {
    mesh::TriangleMesh side = face;
    for (Eigen::Vector3f& p : side.vertices) p = origin + p.x() * u + p.y() * v;
    room.append(side);
  };
  const Eigen::Vector3f x(4, 0, 0), y(0, 3, 0), z(0, 0, 2.5f);
  add_face({0, 0, 0}, x, y);
  add_face(z, y, x);
  add_face({0, 0, 0}, z, x);
  add_face(y, x, z);
  add_face({0, 0, 0}, y, z);
  add_face(x, z, y);
  return room;
}

/// Writes the folder; returns the room's mesh as written.
inline mesh::TriangleMesh write_view_test_folder(const std::filesystem::path& dir, int n = 10) {
  const mesh::TriangleMesh room = view_test_room(n);
  viewer_export::write_mesh((dir / "mesh.ply").string(), room);
  viewer_export::MeshAttributes error;
  std::vector<float> distance(room.vertices.size());
  for (size_t v = 0; v < distance.size(); ++v) distance[v] = 0.05f * std::sin(float(v));
  error.scalars.push_back({"signed_distance", distance});
  viewer_export::write_mesh((dir / "mesh_error.ply").string(), room, error);
  // navmesh.ply as `featsense navmesh` writes it: the same vertices with a cost layer.
  viewer_export::MeshAttributes navigation;
  std::vector<float> cost(room.vertices.size());
  for (size_t v = 0; v < cost.size(); ++v) cost[v] = room.vertices[v].z() / 2.5f;
  navigation.scalars.push_back({"cost", cost});
  viewer_export::write_mesh((dir / "navmesh.ply").string(), room, navigation);
  std::ofstream tum(dir / "trajectory.tum");
  for (int i = 0; i <= 10; ++i) tum << i * 0.1 << " " << 0.5 + 0.3 * i << " 1.5 1.2 0 0 0 1\n";
  // Not a real picture: the server passes the bytes on as they are.
  std::ofstream(dir / "topdown.png", std::ios::binary) << "\x89PNG\r\n\x1a\nplan";
  return room;
}

}  // namespace featsense::test
