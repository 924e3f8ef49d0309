// glTF/GLB export: assimp re-imports the positions in our frame within 1 mm (10 km from the
// origin too), colours and normals survive, and the Khronos validator finds no errors.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "common/gltf_validator.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"
#include "featsense/viewer_export/gltf_mesh_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::test {
namespace {

/// A tilted quad of two triangles at `offset`, with colours and a layer.
mesh::TriangleMesh quad_at(const Eigen::Vector3f& offset,
                           viewer_export::MeshAttributes* attributes) {
  mesh::TriangleMesh m;
  m.vertices = {{0, 0, 0}, {2, 0, 0.5f}, {2, 3, 1}, {0, 3, 0.25f}};
  for (Eigen::Vector3f& v : m.vertices) v += offset;
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  attributes->colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {10, 20, 30}};
  attributes->scalars = {{"cost", {0.0f, 0.25f, 0.5f, 1.0f}}};
  return m;
}

class GltfMeshIo : public ::testing::TestWithParam<std::string> {};

TEST_P(GltfMeshIo, ReimportsWithinAMillimetreFarFromTheOrigin) {
  const std::filesystem::path dir = scratch_dir("gltf_far");
  for (const Eigen::Vector3f& offset :
       {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(10000, -10000, 300),
        Eigen::Vector3f(-10000.3f, 10000.7f, -25)}) {
    viewer_export::MeshAttributes attributes;
    const mesh::TriangleMesh written = quad_at(offset, &attributes);
    const std::string path = (dir / ("quad" + GetParam())).string();
    viewer_export::write_mesh(path, written, attributes);
    viewer_export::MeshAttributes read_attributes;
    const mesh::TriangleMesh read = viewer_export::read_mesh(path, &read_attributes);
    ASSERT_EQ(read.vertices.size(), written.vertices.size());
    ASSERT_EQ(read.triangles, written.triangles);
    for (size_t i = 0; i < read.vertices.size(); ++i) {
      EXPECT_LT((read.vertices[i].cast<double>() - written.vertices[i].cast<double>()).norm(), 1e-3)
          << "offset " << offset.transpose() << " vertex " << i;
    }
    EXPECT_EQ(read_attributes.colors, attributes.colors);
    // Normals come back in our frame: the quad's first face by hand.
    ASSERT_TRUE(read.has_normals());
    const Eigen::Vector3f face = (written.vertices[1] - written.vertices[0])
                                     .cross(written.vertices[2] - written.vertices[0])
                                     .normalized();
    EXPECT_GT(read.normals[1].dot(face), 0.999f);
    expect_valid(path);
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, GltfMeshIo, ::testing::Values(".glb", ".gltf"));

TEST(GltfMeshIoOrigin, ExtrasSayTheOffset) {
  const std::filesystem::path dir = scratch_dir("gltf_extras");
  viewer_export::MeshAttributes attributes;
  const mesh::TriangleMesh written = quad_at({10000, 20000, 30}, &attributes);
  const std::string path = (dir / "quad.gltf").string();
  viewer_export::write_mesh(path, written, attributes);
  std::ifstream in(path);
  const nlohmann::json gltf = nlohmann::json::parse(in);
  // Bounding-box centre (10001, 20001.5, 30.5) rounded to whole metres.
  const nlohmann::json origin = gltf["nodes"][0]["extras"]["featsense_origin_map_m"];
  EXPECT_EQ(origin, nlohmann::json({10001.0, 20002.0, 31.0}));
  // Y up: translation (x, z, -y).
  EXPECT_EQ(gltf["nodes"][0]["translation"], nlohmann::json({10001.0, 31.0, -20002.0}));
  EXPECT_TRUE(gltf["meshes"][0]["primitives"][0]["attributes"].contains("_COST"));
}

TEST(GltfMeshIoOrigin, PointCloudIsValid) {
  const std::filesystem::path dir = scratch_dir("gltf_points");
  mesh::TriangleMesh cloud;
  cloud.vertices = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9.5f}};
  const std::string path = (dir / "cloud.glb").string();
  viewer_export::write_mesh(path, cloud);
  expect_valid(path);
  EXPECT_GT(std::filesystem::file_size(path), 3 * 3 * sizeof(float));
}

// The validation of the other tests is worth something only if the validator, run as they run
// it, finds errors where there are some: a file it accepts, then the same file with its
// positions said to be far more than its buffer holds.
TEST(GltfValidator, RejectsABrokenFile) {
  if (!validator_present()) {
    GTEST_SKIP() << "node or gltf-validator missing (npm install in test/tools): the glTF files "
                    "of this suite were not validated";
  }
  const std::filesystem::path dir = scratch_dir("gltf_broken");
  viewer_export::MeshAttributes attributes;
  const std::string good = (dir / "quad.gltf").string();
  viewer_export::write_mesh(good, quad_at({0, 0, 0}, &attributes), attributes);
  const ValidatorRun accepted = run_validator(good);
  EXPECT_EQ(accepted.status, 0) << accepted.output;
  EXPECT_EQ(nlohmann::json::parse(accepted.output)["errors"], 0) << accepted.output;

  nlohmann::json gltf = nlohmann::json::parse(std::ifstream(good));
  const int position = gltf["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
  gltf["accessors"][static_cast<size_t>(position)]["count"] = 1000000;
  const std::string broken = (dir / "broken.gltf").string();  // its buffer is still quad.bin
  std::ofstream(broken) << gltf.dump();
  const ValidatorRun rejected = run_validator(broken);
  EXPECT_EQ(rejected.status, 1) << rejected.output;
  const nlohmann::json report = nlohmann::json::parse(rejected.output);
  EXPECT_GT(report["errors"].get<int>(), 0) << rejected.output;
}

}  // namespace
}  // namespace featsense::test
