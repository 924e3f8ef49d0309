#include "localize_plan.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/viewer_export/plan_view.hpp"
#include "map_outputs.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;
using mapping::LocalizedScan;
using mapping::LocalizeStatus;
using viewer_export::PlanPath;

const Eigen::Vector3d kGap = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());

/// The positions of the scans `keep` says yes to, a gap for every other.
template <typename Keep>
PlanPath path_where(const std::vector<LocalizedScan>& scans, PlanPath::Kind kind, const char* label,
                    Keep keep) {
  PlanPath path;
  path.kind = kind;
  path.label = label;
  for (size_t i = 0; i < scans.size(); ++i) {
    const bool posed = scans[i].T_map_sensor.has_value();
    path.positions_m.push_back(posed && keep(i) ? scans[i].T_map_sensor->translation() : kGap);
  }
  return path;
}

bool has_position(const PlanPath& path) {
  for (const Eigen::Vector3d& p : path.positions_m)
    if (p.allFinite()) return true;
  return false;
}

}  // namespace

nlohmann::json write_localize_plan(const LocalizeRun& run,
                                   const std::optional<slam::Trajectory>& truth,
                                   const fs::path& folder, double margin_m) {
  const std::vector<LocalizedScan>& scans = run.scans;
  const auto status = [&](size_t i) {
    return i < scans.size() ? scans[i].status : LocalizeStatus::kLost;
  };
  std::vector<PlanPath> paths;
  paths.push_back(path_where(scans, PlanPath::Kind::kEstimate, "localized",
                             [&](size_t i) { return status(i) == LocalizeStatus::kLocalized; }));
  // The odometry's stretches joined to the localized poses at their ends, so that the
  // amber and the red meet.
  paths.push_back(path_where(scans, PlanPath::Kind::kUncertain, "on odometry", [&](size_t i) {
    return status(i) == LocalizeStatus::kOdometry ||
           (i > 0 && status(i - 1) == LocalizeStatus::kOdometry) ||
           status(i + 1) == LocalizeStatus::kOdometry;
  }));
  Eigen::AlignedBox3d box;
  for (const PlanPath& path : paths)
    for (const Eigen::Vector3d& p : path.positions_m)
      if (p.allFinite()) box.extend(p);
  if (box.isEmpty()) return {{"file", nullptr}, {"why_not", "no scan was given a pose"}};
  if (!has_position(paths[1])) paths.pop_back();
  if (truth) {
    // The truth where the scans were, lost ones too: where the sensor went while unposed.
    const slam::PoseInterpolator true_pose(*truth);
    PlanPath truth_path;
    truth_path.kind = PlanPath::Kind::kTruth;
    truth_path.label = "truth";
    for (const LocalizedScan& scan : scans) {
      const std::optional<Eigen::Isometry3d> T = true_pose.at(scan.stamp_ns);
      truth_path.positions_m.push_back(T ? T->translation() : kGap);
    }
    if (has_position(truth_path)) paths.insert(paths.begin(), truth_path);
  }

  const auto start = std::chrono::steady_clock::now();
  mesh::MeshingSettings meshing;
  const Eigen::Vector3d margin(margin_m, margin_m, margin_m);
  meshing.bbox = Eigen::AlignedBox3d(box.min() - margin, box.max() + margin);
  storage::StoreSettings store_settings;
  store_settings.cache_bytes = std::size_t{128} << 20;
  storage::Hdf5ChunkStore store(run.map, store_settings);  // read only
  mesh::MeshingStats stats;
  const mesh::TriangleMesh mesh = mesh::extract_mesh(store, meshing, &stats);
  if (mesh.triangles.empty())
    return {{"file", nullptr}, {"why_not", "the map holds no surface around the path"}};
  const viewer_export::PlanView view = viewer_export::write_plan_view_png(
      mesh, paths, (folder / "topdown.png").string(), viewer_export::PlanViewSettings{});
  nlohmann::json json = plan_json(view, "topdown.png");
  json["margin_m"] = margin_m;
  json["triangles"] = mesh.triangles.size();
  json["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return json;
}

}  // namespace featsense::app
