#include "map_pass.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>

#include "featsense/tsdf/integrator.hpp"
#include "map_store.hpp"
#include "stop_signal.hpp"

namespace featsense::app {
namespace {

tsdf::Vec3 position_of(const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d t = pose.translation();
  return {static_cast<float>(t.x()), static_cast<float>(t.y()), static_cast<float>(t.z())};
}

}  // namespace

MapPassOutput run_map_pass(slam::ScanSource& source, slam::ScanLocator& locator,
                           const PipelineSettings& pipeline, config::Config& config,
                           const MapStoreRequest& request) {
  MapPassOutput out;
  const StopSignal stop_signal;
  if (!pipeline.integrate) {
    out.result = run_map_pipeline(source, locator, MapOpener(), pipeline);
    return out;
  }
  MapStore map_store = open_map_store(request.path, config, request.sensor_name,
                                      request.continue_from, request.overwrite);
  storage::Hdf5ChunkStore& store = *map_store.store;
  out.continued_chunks = map_store.continued_chunks;
  const tsdf::TsdfSettings settings =
      tsdf::TsdfSettings::from_config(config.map, source.info().sensor);
  std::unique_ptr<tsdf::Integrator> integrator;
  std::unique_ptr<storage::ShiftingMap> map;
  const MapOpener open_map = [&](const LocatedScan& first) -> storage::ShiftingMap& {
    integrator =
        tsdf::make_integrator(config.map.backend, settings,
                              position_of(first.placement.T_map_sensor), &out.backend_reason);
    spdlog::info("TSDF: {}", out.backend_reason);
    map = std::make_unique<storage::ShiftingMap>(*integrator, store, config.map.shift_threshold_m);
    return *map;
  };
  try {
    out.result = run_map_pipeline(source, locator, open_map, pipeline);
  } catch (...) {
    // Whatever was integrated goes to disk before the error is reported.
    try {
      if (map) map->sync();
      store.close();
    } catch (const std::exception& e) {
      spdlog::error("could not write the map after the failure: {}", e.what());
    }
    throw;
  }
  if (map) {
    const auto start = std::chrono::steady_clock::now();
    map->sync();
    out.final_flush_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    out.map = map->stats();
  }
  slam::Trajectory all_poses = map_store.earlier_poses;
  for (size_t i = 0; i < out.result.poses.size(); ++i)
    all_poses.push_back(out.result.poses.stamps_ns[i], out.result.poses.poses[i]);
  store.write_trajectory(to_store_poses(all_poses));
  const std::vector<slam::loops::KeyframeRecord> no_keyframes;
  const std::vector<slam::loops::KeyframeRecord>& keyframes =
      request.keyframes ? *request.keyframes
                        : (out.result.loops ? out.result.loops->keyframes : no_keyframes);
  record_session(store, request.session, out.result.poses, keyframes);
  out.map_chunks = store.keys().size();
  store.close();
  if (integrator) {
    out.backend = integrator->backend_name();
    if (out.backend == "cuda") out.device_memory_bytes = integrator->memory_bytes();
  }
  return out;
}

}  // namespace featsense::app
