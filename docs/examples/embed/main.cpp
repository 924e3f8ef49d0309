// Mapping from your own program: the built-in example recording (an OS1-128 moving through a
// box room) fed scan by scan into a featsense Mapper, which estimates the poses with its
// odometry, integrates the TSDF map and writes it to OUT/map.h5; then the map is meshed into
// OUT/mesh.ply. A robot's node does the same with the scans its driver hands it.
//
// Usage: featsense_embed OUT_DIR

#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>

#include "featsense/mapping/mapper.hpp"
#include "featsense/mapping/recording.hpp"
#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  namespace fs = std::filesystem;
  namespace mapping = featsense::mapping;
  try {
    const fs::path out(argv[1]);
    fs::create_directories(out);

    // An empty path opens the built-in example; any recording featsense reads works here.
    featsense::config::Config config;
    std::unique_ptr<featsense::slam::ScanSource> source = mapping::open_recording("", config);

    mapping::MapperSettings settings;
    settings.config = config;
    settings.config.map.voxel_size_m = 0.1;  // a coarse map: the example runs in seconds
    settings.sensor = source->info().sensor;
    settings.map_path = out / "map.h5";
    settings.overwrite = true;
    settings.session = {"built-in example", source->info().format, "odometry"};
    mapping::RunEvents events;
    events.log = [](mapping::LogLevel, const std::string& text) {
      std::printf("featsense: %s\n", text.c_str());
    };
    mapping::Mapper mapper(settings, events);

    // Scan by scan, as a live driver hands them over.
    while (std::optional<featsense::slam::Scan> scan = source->next()) {
      const mapping::ScanUpdate update = mapper.add_scan(std::move(*scan));
      const Eigen::Vector3d at = update.placement.T_map_sensor.translation();
      std::printf("scan %llu: %s at (%.3f, %.3f, %.3f) m, %zu mapped\n",
                  static_cast<unsigned long long>(update.placement.sequence),
                  update.placed ? "placed" : "skipped", at.x(), at.y(), at.z(),
                  update.scans_mapped);
    }
    const mapping::MapResult result = mapper.finish();
    std::printf("%zu scans mapped (%s), %zu chunks in %s\n", result.mapped().frames_mapped,
                result.poses.c_str(), result.mapped().map_chunks,
                settings.map_path.string().c_str());

    featsense::storage::Hdf5ChunkStore store(settings.map_path);
    const featsense::mesh::TriangleMesh mesh =
        featsense::mesh::extract_mesh(store, featsense::mesh::MeshingSettings{});
    featsense::viewer_export::write_ply_mesh((out / "mesh.ply").string(), mesh);
    std::printf("mesh: %zu triangles in %s\n", mesh.triangles.size(),
                (out / "mesh.ply").string().c_str());
    return result.mapped().frames_mapped > 0 && !mesh.triangles.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "featsense_embed: %s\n", e.what());
    return 1;
  }
}
