// featsense navmesh MESH -o NAV: per-vertex traversability layers for mesh-based navigation.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "featsense/mesh/navigation_layers.hpp"
#include "featsense/viewer_export/mesh_nav_h5_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::app {
namespace {

struct NavmeshOptions {
  std::string input;
  std::string output;
  mesh::NavigationSettings settings;
};

/// Green (free) through yellow to red (cost just below 1); lethal vertices dark red.
Eigen::Matrix<uint8_t, 3, 1> cost_colour(float cost) {
  if (cost >= 1.0f) return {128, 0, 0};
  const float c = std::clamp(cost, 0.0f, 1.0f);
  const auto byte = [](float v) { return static_cast<uint8_t>(std::lround(v * 255.0f)); };
  return c < 0.5f ? Eigen::Matrix<uint8_t, 3, 1>(byte(2.0f * c), 255, 0)
                  : Eigen::Matrix<uint8_t, 3, 1>(255, byte(2.0f - 2.0f * c), 0);
}

void run_navmesh(const NavmeshOptions& options) {
  mesh::TriangleMesh mesh = viewer_export::read_mesh(options.input);
  const mesh::NavigationLayers layers = mesh::compute_navigation_layers(mesh, options.settings);
  if (!mesh.has_normals()) mesh.normals = mesh::vertex_normals(mesh);

  viewer_export::MeshAttributes attributes;
  attributes.scalars = {{"inclination_deg", layers.inclination_deg},
                        {"roughness_deg", layers.roughness_deg},
                        {"height_diff_m", layers.height_diff_m},
                        {"cost", layers.cost}};
  // Lethal per vertex too: the formats without face layers (PLY, glTF) carry it this way.
  std::vector<float> lethal_vertices(mesh.vertices.size(), 0.0f);
  std::vector<float> lethal_faces(layers.lethal_faces.size(), 0.0f);
  size_t lethal_count = 0;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (layers.lethal_faces[f] == 0) continue;
    lethal_faces[f] = 1.0f;
    ++lethal_count;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<size_t>(mesh.triangles[f][k]);
      if (layers.cost[v] >= 1.0f) lethal_vertices[v] = 1.0f;
    }
  }
  attributes.scalars.push_back({"lethal", lethal_vertices});
  for (const float cost : layers.cost) attributes.colors.push_back(cost_colour(cost));

  if (viewer_export::mesh_extension(options.output) == ".h5") {
    viewer_export::write_mesh_nav_h5(options.output, mesh, attributes, {{"lethal", lethal_faces}});
  } else {
    viewer_export::write_mesh(options.output, mesh, attributes);
  }
  std::printf(
      "%s: %zu vertices, %zu triangles, %zu lethal (slope > %.1f deg or step > %.2f m "
      "within %.2f m)\n",
      options.output.c_str(), mesh.vertices.size(), mesh.triangles.size(), lethal_count,
      options.settings.max_slope_deg, options.settings.max_step_m, options.settings.radius_m);
}

}  // namespace

Command register_navmesh(CLI::App& app, const CliContext& /*context*/) {
  auto options = std::make_shared<NavmeshOptions>();
  CLI::App* command = app.add_subcommand(
      "navmesh",
      "Traversability layers of a ground mesh (inclination_deg, roughness_deg, height_diff_m, "
      "cost 0..1 with 1 lethal, lethal) as scalar layers, coloured by cost");
  command->add_option("MESH", options->input, "Input mesh (.ply, .obj, .glb, .gltf)")->required();
  command
      ->add_option("-o,--output", options->output,
                   "Output: .ply .glb .gltf .obj (colours only) or .h5 (mesh navigation layout, "
                   "lethal faces under face_attributes)")
      ->required();
  command
      ->add_option("--max-slope-deg", options->settings.max_slope_deg,
                   "Steeper is lethal, degrees from up")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--max-step", options->settings.max_step_m,
                   "A larger height difference within the radius is lethal, metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--radius", options->settings.radius_m,
                   "Neighbourhood of roughness and height difference, metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  return {command, [options] { run_navmesh(*options); }};
}

}  // namespace featsense::app
