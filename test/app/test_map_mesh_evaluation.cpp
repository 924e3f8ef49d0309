// The mesh of a map scored against a reference surface, as mapped and aligned with the true
// path: a rigid motion of the whole map costs the first, not the second.
#include <gtest/gtest.h>

#include <filesystem>

#include "featsense/viewer_export/mesh_writer.hpp"
#include "map_outputs.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

mesh::TriangleMesh room() {
  mesh::TriangleMesh m;
  m.add_box({-10.f, -8.f, 0.f}, {10.f, 8.f, 3.f}, m.add_part("room", 0.5f));
  m.add_box({-1.f, -1.f, 0.f}, {1.f, 1.f, 3.f}, m.add_part("pillar", 0.5f));
  return m;
}

TEST(MapMeshEvaluation, AlignedScoreUndoesARigidMotionOfTheMap) {
  const fs::path dir = fs::temp_directory_path() / "featsense_map_mesh_evaluation";
  fs::create_directories(dir);
  MeshReferences references;
  references.surface = dir / "reference.ply";
  viewer_export::write_mesh(references.surface->string(), room());

  // The map's frame is off the truth's by a tilt of 0.5 deg and 10 cm: T_truth_estimate.
  Eigen::Isometry3d T_truth_estimate = Eigen::Isometry3d::Identity();
  T_truth_estimate.linear() =
      Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d(1, 1, 0).normalized())
          .toRotationMatrix();
  T_truth_estimate.translation() = Eigen::Vector3d(0.1, -0.05, 0.02);
  mesh::TriangleMesh mapped = room();
  const Eigen::Isometry3f T_estimate_truth = T_truth_estimate.inverse().cast<float>();
  for (Eigen::Vector3f& v : mapped.vertices) v = T_estimate_truth * v;

  const std::optional<nlohmann::json> scored =
      evaluate_map_mesh(mapped, references, T_truth_estimate);
  ASSERT_TRUE(scored.has_value());
  const double as_mapped = (*scored)["accuracy"]["mean_abs"].get<double>();
  ASSERT_TRUE(scored->contains("aligned"));
  const double aligned = (*scored)["aligned"]["accuracy"]["mean_abs"].get<double>();
  EXPECT_GT(as_mapped, 0.03);  // centimetres: the tilt and the shift
  EXPECT_LT(aligned, 1e-4);    // the same surface once aligned

  const std::optional<nlohmann::json> plain = evaluate_map_mesh(mapped, references);
  ASSERT_TRUE(plain.has_value());
  EXPECT_FALSE(plain->contains("aligned"));
  EXPECT_DOUBLE_EQ((*plain)["accuracy"]["mean_abs"].get<double>(), as_mapped);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace featsense::app
