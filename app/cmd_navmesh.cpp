// featsense navmesh MESH -o NAV: per-vertex traversability layers for mesh-based navigation.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "featsense/mesh/navigation_layers.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "featsense/viewer_export/surface_file_regions.hpp"
#include "navigation_files.hpp"

namespace featsense::app {
namespace {

struct NavmeshOptions {
  std::string input;
  std::string output;
  std::string format = "ply";  ///< of a tile set's tiles
  mesh::NavigationSettings settings;
};

void run_navmesh(const NavmeshOptions& options, bool quiet) {
  if (viewer_export::is_tile_set(options.input)) {
    // A tile at a time (with its neighbours): the memory of a few tiles, whatever the map.
    // A folder's name may hold a dot (nav_2.5): only a mesh format's extension names a file.
    if (viewer_export::is_writable_mesh_path(options.output)) {
      throw std::runtime_error(options.input +
                               " is a tile set: -o names a folder for its "
                               "tiles' layers, not a file (" +
                               options.output + ")");
    }
    const nlohmann::json index = write_navigation_tiles(
        options.input, options.output, "." + options.format, options.settings, quiet);
    if (!quiet) {
      std::printf(
          "%s: %zu tiles, %zu triangles, %zu lethal (slope > %.1f deg or step > %.2f m "
          "within %.2f m)\n",
          options.output.c_str(), index["tiles"].size(), index["triangles"].get<size_t>(),
          index["lethal_triangles"].get<size_t>(), options.settings.max_slope_deg,
          options.settings.max_step_m, options.settings.radius_m);
    }
    return;
  }
  mesh::TriangleMesh mesh = viewer_export::read_mesh(options.input);
  const mesh::NavigationLayers layers = mesh::compute_navigation_layers(mesh, options.settings);
  const size_t lethal_count = write_navigation_mesh(options.output, mesh, layers);
  std::printf(
      "%s: %zu vertices, %zu triangles, %zu lethal (slope > %.1f deg or step > %.2f m "
      "within %.2f m)\n",
      options.output.c_str(), mesh.vertices.size(), mesh.triangles.size(), lethal_count,
      options.settings.max_slope_deg, options.settings.max_step_m, options.settings.radius_m);
}

}  // namespace

Command register_navmesh(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<NavmeshOptions>();
  CLI::App* command = app.add_subcommand(
      "navmesh",
      "Traversability layers of a ground mesh (inclination_deg, roughness_deg, height_diff_m, "
      "cost 0..1 with 1 lethal, lethal) as scalar layers, coloured by cost");
  command
      ->add_option("MESH", options->input,
                   "Input mesh (.ply, .obj, .glb, .gltf) or a tile set's folder (mesh --tiles)")
      ->required();
  command
      ->add_option("-o,--output", options->output,
                   "Output: .ply .glb .gltf .obj (colours only) or .h5 (mesh navigation layout, "
                   "lethal faces under face_attributes); for a tile set, a folder")
      ->required();
  command
      ->add_option("--tile-format", options->format,
                   "A tile set's tiles' layers as ply, glb, gltf, obj or h5")
      ->check(CLI::IsMember({"ply", "glb", "gltf", "obj", "h5"}))
      ->capture_default_str();
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
  return {command, [options, &context] { run_navmesh(*options, context.quiet); }};
}

}  // namespace featsense::app
