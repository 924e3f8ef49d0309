// featsense export MESH -o FILE: a mesh in another format (PLY, OBJ, glTF/GLB, navigation HDF5).

#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::app {
namespace {

struct ExportOptions {
  std::string input;
  std::string output;
  bool ascii = false;
};

void run_export(const ExportOptions& options) {
  viewer_export::MeshAttributes attributes;
  const mesh::TriangleMesh mesh = viewer_export::read_mesh(options.input, &attributes);
  viewer_export::MeshWriteSettings settings;
  settings.ply_ascii = options.ascii;
  viewer_export::write_mesh(options.output, mesh, attributes, settings);
  std::printf("%s: %zu vertices, %zu triangles\n", options.output.c_str(), mesh.vertices.size(),
              mesh.triangles.size());
}

}  // namespace

Command register_export(CLI::App& app, const CliContext& /*context*/) {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* command = app.add_subcommand(
      "export", "Write a mesh as PLY, OBJ, glTF/GLB or the mesh navigation HDF5 layout");
  command->add_option("MESH", options->input, "Input mesh (.ply, .obj, .glb, .gltf)")->required();
  command
      ->add_option("-o,--output", options->output,
                   "Output file; the format follows the extension: .ply .obj .glb .gltf .h5")
      ->required();
  command->add_flag("--ascii", options->ascii, "PLY as ascii instead of binary little-endian");
  return {command, [options] { run_export(*options); }};
}

}  // namespace featsense::app
