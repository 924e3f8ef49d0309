// featsense export MESH -o FILE: a mesh in another format (PLY, OBJ, glTF/GLB, navigation HDF5);
// featsense export MAP.h5 -o MAP.vdb (and back): the map for OpenVDB tools.

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/storage/vdb_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::app {
namespace {

struct ExportOptions {
  std::string input;
  std::string output;
  bool ascii = false;
};

bool has_extension(const std::string& path, const char* extension) {
  return std::filesystem::path(path).extension() == extension;
}

/// A map (not a mesh): map.h5 -> .vdb (float grids "tsdf" and "weight" in metres), or a .vdb
/// back into a new map store.
void export_map(const ExportOptions& options) {
  if (has_extension(options.input, ".h5") && has_extension(options.output, ".vdb")) {
    storage::Hdf5ChunkStore store(options.input);
    const storage::VdbExportStats stats = storage::export_vdb(store, options.output);
    std::printf("%s: %zu chunks, %zu observed voxels\n", options.output.c_str(), stats.chunks,
                stats.active_voxels);
    return;
  }
  if (has_extension(options.input, ".vdb") && has_extension(options.output, ".h5")) {
    storage::MapMetadata metadata = storage::read_vdb_metadata(options.input);
    metadata.max_weight = 0.0;  // unknown to a .vdb
    metadata.sensor = "unknown (imported from " + options.input + ")";
    storage::Hdf5ChunkStore store(options.output, storage::OpenMode::kCreate, metadata);
    const storage::VdbExportStats stats = storage::import_vdb(options.input, store);
    store.close();
    std::printf("%s: %zu chunks, %zu observed voxels\n", options.output.c_str(), stats.chunks,
                stats.active_voxels);
    return;
  }
  throw std::runtime_error("a map converts between .h5 and .vdb: " + options.input + " -> " +
                           options.output);
}

void run_export(const ExportOptions& options) {
  if (has_extension(options.input, ".h5") || has_extension(options.input, ".vdb")) {
    export_map(options);
    return;
  }
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
      "export",
      "Write a mesh as PLY, OBJ, glTF/GLB or the mesh navigation HDF5 layout, or a map "
      "(map.h5) as OpenVDB (.vdb) and back");
  command
      ->add_option("MESH", options->input,
                   "Input mesh (.ply, .obj, .glb, .gltf), or a map (.h5 store, .vdb)")
      ->required();
  command
      ->add_option("-o,--output", options->output,
                   "Output file; the format follows the extension: .ply .obj .glb .gltf .h5")
      ->required();
  command->add_flag("--ascii", options->ascii, "PLY as ascii instead of binary little-endian");
  return {command, [options] { run_export(*options); }};
}

}  // namespace featsense::app
