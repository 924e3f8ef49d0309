#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"
#include "mesh/mesh_test_shapes.hpp"

namespace featsense::test {
namespace {

/// A TUM file of `count` poses at 10 Hz from t0 on a circle of radius 10 m (yawing along),
/// each position shifted by `shift` and the stamps by `stamp_shift_s`.
void write_circle_tum(const std::filesystem::path& path, int count, double stamp_shift_s,
                      double noise_m) {
  std::ofstream out(path);
  char line[256];
  for (int i = 0; i < count; ++i) {
    const double t = 0.1 * i;
    const double a = 0.2 * t;
    const double n = (i % 2 == 0 ? 1 : -1) * noise_m;  // along z, alternating
    std::snprintf(line, sizeof line, "%.9f %.9f %.9f %.9f 0 0 %.12f %.12f\n",
                  100 + t + stamp_shift_s, 10 * std::cos(a), 10 * std::sin(a), 0.01 * i + n,
                  std::sin(a / 2), std::cos(a / 2));
    out << line;
  }
}

TEST(CliEval, TrajReportsApeRpeAndPairsAsJson) {
  const auto dir = scratch_dir("cli_eval_traj");
  write_circle_tum(dir / "gt.tum", 300, 0.0, 0.0);
  write_circle_tum(dir / "est.tum", 300, 0.003, 0.05);
  const CommandResult r =
      run_featsense("eval traj " + (dir / "est.tum").string() + " " + (dir / "gt.tum").string() +
                    " --align none --json " + (dir / "e.json").string() + " --aligned-out " +
                    (dir / "aligned.tum").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("APE:"), std::string::npos) << r.output;
  const nlohmann::json j = read_json(dir / "e.json");
  EXPECT_EQ(j["pairs"], 300);
  for (const char* key : {"rmse", "mean", "median", "std", "min", "max"}) {
    EXPECT_NEAR(j["ape"][key].get<double>(), std::string(key) == "std" ? 0.0 : 0.05, 1e-6) << key;
  }
  // Consecutive z errors alternate by 0.1 m; rotated into the sensor frame the norm stays 0.1.
  EXPECT_NEAR(j["rpe"]["mean"].get<double>(), 0.1, 1e-6);
  EXPECT_TRUE(j["rpe"].contains("rmse"));
  EXPECT_FALSE(j.contains("kitti"));  // about 60 m of path
  EXPECT_TRUE(std::filesystem::exists(dir / "aligned.tum"));
}

TEST(CliEval, TrajReadsKittiPairedByIndexOrByTimes) {
  const auto dir = scratch_dir("cli_eval_kitti");
  // Ground truth along x, 1 m a frame, 150 frames; the estimate runs 2 % long.
  std::ofstream gt(dir / "gt.txt");
  std::ofstream est(dir / "est.txt");
  std::ofstream times(dir / "times.txt");
  for (int i = 0; i < 150; ++i) {
    gt << "1 0 0 " << i << " 0 1 0 0 0 0 1 0\n";
    est << "1 0 0 " << 1.02 * i << " 0 1 0 0 0 0 1 0\n";
    times << 0.1 * i << "\n";
  }
  gt.close();
  est.close();
  times.close();
  const std::string files = (dir / "est.txt").string() + " " + (dir / "gt.txt").string();
  const CommandResult r =
      run_featsense("eval traj " + files + " --format kitti --align none --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["pairs"], 150);
  EXPECT_TRUE(j["association"]["by_index"].get<bool>());
  EXPECT_NEAR(j["ape"]["max"].get<double>(), 0.02 * 149, 1e-6);
  EXPECT_NEAR(j["rpe"]["mean"].get<double>(), 0.02, 1e-6);
  // 100 m segments from frames 0..40 span 101 m: 2 % of 101 m over 100 m.
  EXPECT_NEAR(j["kitti"]["t_err_pct"].get<double>(), 2.0 * 1.01, 1e-6);
  const CommandResult timed =
      run_featsense("eval traj " + files + " --format kitti --align none --json - --est-times " +
                    (dir / "times.txt").string() + " --gt-times " + (dir / "times.txt").string());
  ASSERT_EQ(timed.exit_code, 0) << timed.output;
  EXPECT_FALSE(nlohmann::json::parse(timed.output)["association"]["by_index"].get<bool>());
}

TEST(CliEval, TrajErrorsAreClear) {
  const auto dir = scratch_dir("cli_eval_traj_errors");
  write_circle_tum(dir / "gt.tum", 50, 0.0, 0.0);
  write_circle_tum(dir / "late.tum", 50, 1000.0, 0.0);
  const CommandResult late =
      run_featsense("eval traj " + (dir / "late.tum").string() + " " + (dir / "gt.tum").string());
  EXPECT_EQ(late.exit_code, 1);
  EXPECT_NE(late.output.find("time ranges do not overlap"), std::string::npos) << late.output;
  write_circle_tum(dir / "off.tum", 50, 0.05, 0.0);
  const CommandResult none =
      run_featsense("eval traj " + (dir / "off.tum").string() + " " + (dir / "gt.tum").string());
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.output.find("no pose pair within 0.010000 s"), std::string::npos) << none.output;
  std::ofstream(dir / "bad.tum") << "1 2 3\n";
  const CommandResult bad =
      run_featsense("eval traj " + (dir / "bad.tum").string() + " " + (dir / "gt.tum").string());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("bad.tum:1: a line of 3 numbers is neither TUM (8) nor KITTI (12)"),
            std::string::npos)
      << bad.output;
  const CommandResult bad_tum = run_featsense(
      "eval traj --format tum " + (dir / "bad.tum").string() + " " + (dir / "gt.tum").string());
  EXPECT_EQ(bad_tum.exit_code, 1);
  EXPECT_NE(bad_tum.output.find("bad.tum:1: expected 8 numbers"), std::string::npos)
      << bad_tum.output;
}

TEST(CliEval, MeshReportsAccuracyCompletenessAndWritesScalarFields) {
  const auto dir = scratch_dir("cli_eval_mesh");
  viewer_export::write_ply_mesh((dir / "ref.ply").string(), grid_plane(-1, 1, -1, 1, 0, 4));
  // The estimate: the left half of the plane, lifted by 1 cm.
  viewer_export::write_ply_mesh((dir / "est.ply").string(), grid_plane(-1, 0, -1, 1, 0.01f, 4));
  const CommandResult r = run_featsense(
      "eval mesh " + (dir / "est.ply").string() + " " + (dir / "ref.ply").string() + " --json " +
      (dir / "m.json").string() + " --ply-out " + (dir / "d.ply").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = read_json(dir / "m.json");
  EXPECT_EQ(j["points"], 25);
  EXPECT_NEAR(j["accuracy"]["mean_abs"].get<double>(), 0.01, 1e-6);
  EXPECT_NEAR(j["accuracy"]["mean_signed"].get<double>(), 0.01, 1e-6);
  EXPECT_NEAR(j["accuracy"]["p95"].get<double>(), 0.01, 1e-6);
  // Reference within t of the estimate: x <= sqrt(t^2 - 0.01^2), a share of (1 + that) / 2.
  for (const auto& [key, t] :
       {std::pair<std::string, double>{"0.02", 0.02}, {"0.05", 0.05}, {"0.10", 0.10}}) {
    const double expected = 0.5 * (1.0 + std::sqrt(t * t - 1e-4));
    EXPECT_NEAR(j["completeness"][key].get<double>(), expected, 0.01) << key;
    EXPECT_TRUE(j["fscore"].contains(key));
  }
  std::ostringstream text;
  text << std::ifstream(dir / "d.ply", std::ios::binary).rdbuf();
  const std::string ply = text.str();
  EXPECT_NE(ply.find("property float scalar_distance"), std::string::npos);
  EXPECT_NE(ply.find("property float scalar_signed_distance"), std::string::npos);
}

TEST(CliEval, MeshErrorsAreClear) {
  const auto dir = scratch_dir("cli_eval_mesh_errors");
  viewer_export::write_ply_mesh((dir / "est.ply").string(), grid_plane(-1, 1, -1, 1, 0, 2));
  mesh::TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}};
  viewer_export::write_ply_mesh((dir / "flat.ply").string(), flat);
  const CommandResult degenerate =
      run_featsense("eval mesh " + (dir / "est.ply").string() + " " + (dir / "flat.ply").string());
  EXPECT_EQ(degenerate.exit_code, 1);
  EXPECT_NE(degenerate.output.find("degenerate"), std::string::npos) << degenerate.output;
  viewer_export::write_ply_mesh((dir / "empty.ply").string(), mesh::TriangleMesh{});
  const CommandResult empty =
      run_featsense("eval mesh " + (dir / "est.ply").string() + " " + (dir / "empty.ply").string());
  EXPECT_EQ(empty.exit_code, 1);
  EXPECT_NE(empty.output.find("the reference has no vertices"), std::string::npos) << empty.output;
  const CommandResult missing =
      run_featsense("eval mesh " + (dir / "est.ply").string() + " " + (dir / "nope.ply").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("nope.ply: cannot open"), std::string::npos) << missing.output;
}

/// Estimated points near a reference: its vertices moved along the radial direction from the
/// centre by a bias plus seeded Gaussian noise, and some scattered a little sideways.
mesh::TriangleMesh noisy_points(const mesh::TriangleMesh& reference, double bias_m, double noise_m,
                                unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, noise_m);
  mesh::TriangleMesh points;
  for (const Eigen::Vector3f& v : reference.vertices) {
    const Eigen::Vector3d p = v.cast<double>();
    const Eigen::Vector3d sideways(normal(random), normal(random), normal(random));
    points.vertices.push_back(
        (p + (bias_m + normal(random)) * p.normalized() + sideways).cast<float>());
  }
  return points;
}

bool on_path(const std::string& program) {
  return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

/// CloudCompare's mean and std of C2M distances, from its log line
/// "[ComputeDistances] Mean distance = M / std deviation = S".
bool cloudcompare_c2m(const std::filesystem::path& est, const std::filesystem::path& ref,
                      double* mean, double* std_dev, std::string* log) {
  const std::string command = "QT_QPA_PLATFORM=offscreen CloudCompare -SILENT -AUTO_SAVE OFF -O " +
                              est.string() + " -O " + ref.string() + " -C2M_DIST 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return false;
  char buffer[4096];
  while (fgets(buffer, sizeof buffer, pipe) != nullptr) *log += buffer;
  pclose(pipe);
  const size_t at = log->find("Mean distance = ");
  return at != std::string::npos &&
         std::sscanf(log->c_str() + at, "Mean distance = %lf / std deviation = %lf", mean,
                     std_dev) == 2;
}

// Agreement with CloudCompare's cloud-to-mesh distance (-C2M_DIST, signed by the triangles'
// normals) on a sphere, a box and a plane: mean and std within 1 mm.
TEST(CliEval, MeanAndStdMatchCloudCompareC2M) {
  if (!on_path("CloudCompare")) GTEST_SKIP() << "CloudCompare is not installed";
  const auto dir = scratch_dir("cli_eval_cloudcompare");
  struct Case {
    std::string name;
    mesh::TriangleMesh reference;
    double bias_m;
  };
  const std::vector<Case> cases = {{"sphere", icosphere(3.0f, 4), 0.02},
                                   {"box", box_mesh(2.0f), -0.01},
                                   {"plane", grid_plane(-5, 5, -5, 5, 1, 40), 0.03}};
  for (const Case& c : cases) {
    mesh::TriangleMesh reference = c.reference;
    mesh::TriangleMesh points;
    if (c.name == "box") {
      // The box has 8 vertices: take points on its faces instead (seeded), then perturb.
      std::mt19937 random(7);
      std::uniform_real_distribution<float> u(-2.0f, 2.0f);
      for (int i = 0; i < 3000; ++i) {
        Eigen::Vector3f p(u(random), u(random), u(random));
        p[i % 3] = (i % 2 == 0) ? 2.0f : -2.0f;
        points.vertices.push_back(p);
      }
      points = noisy_points(points, c.bias_m, 0.01, 3);
    } else {
      points = noisy_points(reference, c.bias_m, 0.01, 5);
    }
    const auto est = dir / (c.name + "_est.ply");
    const auto ref = dir / (c.name + "_ref.ply");
    viewer_export::write_ply_mesh(est.string(), points);
    viewer_export::write_ply_mesh(ref.string(), reference);
    const CommandResult r =
        run_featsense("eval mesh " + est.string() + " " + ref.string() + " --json -");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json j = nlohmann::json::parse(r.output);
    double cc_mean = 0;
    double cc_std = 0;
    std::string log;
    ASSERT_TRUE(cloudcompare_c2m(est, ref, &cc_mean, &cc_std, &log)) << log;
    const double mean = j["accuracy"]["mean_signed"].get<double>();
    const double std_dev = j["accuracy"]["std_signed"].get<double>();
    EXPECT_NEAR(mean, cc_mean, 1e-3) << c.name;
    EXPECT_NEAR(std_dev, cc_std, 1e-3) << c.name;
    std::printf(
        "[ CloudCompare ] %s: %zu points, featsense mean %.6f std %.6f, CloudCompare "
        "mean %.6f std %.6f\n",
        c.name.c_str(), points.vertices.size(), mean, std_dev, cc_mean, cc_std);
  }
}

// The same on the real scenes of ../shared/data/scenes (concave rooms, thin walls, furniture):
// a share of their vertices moved by a 1 cm bias and 2 cm noise, against the scene mesh.
TEST(CliEval, MeanAndStdMatchCloudCompareC2MOnRealScenes) {
  if (!on_path("CloudCompare")) GTEST_SKIP() << "CloudCompare is not installed";
  for (const std::string scene : {"small_house.ply", "gas_station_with_ground.ply"}) {
    FEATSENSE_SHARED_FILE(reference, "scenes/" + scene);
    const auto dir = scratch_dir("cli_eval_cloudcompare_" + scene);
    // Every 8th vertex keeps CloudCompare's run short.
    mesh::TriangleMesh vertices;
    const mesh::TriangleMesh scene_mesh = viewer_export::read_ply_mesh(reference.string());
    for (size_t i = 0; i < scene_mesh.vertices.size(); i += 8) {
      vertices.vertices.push_back(scene_mesh.vertices[i]);
    }
    const mesh::TriangleMesh points = noisy_points(vertices, 0.01, 0.02, 11);
    const auto est = dir / "est.ply";
    viewer_export::write_ply_mesh(est.string(), points);
    const CommandResult r =
        run_featsense("eval mesh " + est.string() + " " + reference.string() +
                      " --samples-per-m2 100 --json -");  // completeness is not compared here
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json j = nlohmann::json::parse(r.output);
    double cc_mean = 0;
    double cc_std = 0;
    std::string log;
    ASSERT_TRUE(cloudcompare_c2m(est, reference, &cc_mean, &cc_std, &log)) << log;
    const double mean = j["accuracy"]["mean_signed"].get<double>();
    const double std_dev = j["accuracy"]["std_signed"].get<double>();
    EXPECT_NEAR(mean, cc_mean, 1e-3) << scene;
    EXPECT_NEAR(std_dev, cc_std, 1e-3) << scene;
    std::printf(
        "[ CloudCompare ] %s: %zu points, featsense mean %.6f std %.6f, CloudCompare "
        "mean %.6f std %.6f\n",
        scene.c_str(), points.vertices.size(), mean, std_dev, cc_mean, cc_std);
  }
}

}  // namespace
}  // namespace featsense::test
