// The colours of a mesh's error: the diverging map as a pure function, and a GLB whose vertex
// colours are read back byte by byte from the file itself (not through assimp, which would
// hide how they are stored).

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/test_data.hpp"
#include "featsense/viewer_export/error_colours.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::test {
namespace {

using Rgb = std::array<uint8_t, 3>;

TEST(SignedDistanceColour, WhiteOnTheReferenceRedInFrontBlueBehind) {
  EXPECT_EQ(viewer_export::signed_distance_colour(0.0f), (Rgb{255, 255, 255}));
  EXPECT_EQ(viewer_export::signed_distance_colour(0.1f), (Rgb{255, 0, 0}));
  EXPECT_EQ(viewer_export::signed_distance_colour(-0.1f), (Rgb{0, 0, 255}));
  // Half way: half faded, the hue unchanged.
  EXPECT_EQ(viewer_export::signed_distance_colour(0.05f), (Rgb{255, 128, 128}));
  EXPECT_EQ(viewer_export::signed_distance_colour(-0.05f), (Rgb{128, 128, 255}));
}

TEST(SignedDistanceColour, SaturatesBeyondTheLimit) {
  EXPECT_EQ(viewer_export::signed_distance_colour(3.0f), (Rgb{255, 0, 0}));
  EXPECT_EQ(viewer_export::signed_distance_colour(-3.0f), (Rgb{0, 0, 255}));
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(viewer_export::signed_distance_colour(inf), (Rgb{255, 0, 0}));
  EXPECT_EQ(viewer_export::signed_distance_colour(-inf), (Rgb{0, 0, 255}));
  // Another saturation: 1 m.
  EXPECT_EQ(viewer_export::signed_distance_colour(0.5f, 1.0f), (Rgb{255, 128, 128}));
}

TEST(SignedDistanceColour, NoDistanceIsGrey) {
  const Rgb nan = viewer_export::signed_distance_colour(std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(nan, (Rgb{128, 128, 128}));
}

TEST(SignedDistanceColour, ThePlanLegendRunsFromBehindToInFront) {
  const viewer_export::PlanVertexColours colours =
      viewer_export::signed_distance_plan_colours({0.0f, -0.2f});
  EXPECT_EQ(colours.rgb.size(), 2u);
  EXPECT_EQ(colours.rgb[1], (Eigen::Matrix<uint8_t, 3, 1>(0, 0, 255)));
  EXPECT_EQ(colours.low, "behind -10 cm");
  EXPECT_EQ(colours.high, "+10 cm in front");
  EXPECT_EQ(colours.ramp(0.0), (Rgb{0, 0, 255}));
  EXPECT_EQ(colours.ramp(0.5), (Rgb{255, 255, 255}));
  EXPECT_EQ(colours.ramp(1.0), (Rgb{255, 0, 0}));
}

/// A GLB's two chunks: the JSON and the binary buffer.
struct GlbChunks {
  nlohmann::json gltf;
  std::string bin;
};

uint32_t le32(const std::string& bytes, size_t at) {
  uint32_t value = 0;
  std::memcpy(&value, bytes.data() + at, sizeof value);  // the test machines are little-endian
  return value;
}

GlbChunks read_glb(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string file(static_cast<size_t>(in.tellg()), '\0');
  in.seekg(0);
  in.read(file.data(), static_cast<std::streamsize>(file.size()));
  GlbChunks chunks;
  if (file.size() < 20 || file.compare(0, 4, "glTF") != 0) {
    ADD_FAILURE() << path << " is not a GLB";
    return chunks;
  }
  EXPECT_EQ(le32(file, 8), file.size());
  const uint32_t json_length = le32(file, 12);
  EXPECT_EQ(file.compare(16, 4, "JSON"), 0);
  chunks.gltf = nlohmann::json::parse(file.substr(20, json_length));
  const size_t bin_at = 20 + json_length;
  EXPECT_EQ(file.compare(bin_at + 4, 4, std::string("BIN\0", 4)), 0);
  chunks.bin = file.substr(bin_at + 8, le32(file, bin_at));
  return chunks;
}

TEST(ErrorColouredGlb, StoresColour0AsNormalisedBytesPerVertex) {
  mesh::TriangleMesh quad;
  quad.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  viewer_export::MeshAttributes attributes;
  attributes.colors = viewer_export::signed_distance_colours(
      {0.0f, 0.1f, -0.1f, std::numeric_limits<float>::quiet_NaN()});
  const std::string path = (scratch_dir("error_colours_glb") / "quad.glb").string();
  viewer_export::write_mesh(path, quad, attributes);

  const GlbChunks glb = read_glb(path);
  const nlohmann::json& primitive = glb.gltf["meshes"][0]["primitives"][0];
  ASSERT_TRUE(primitive["attributes"].contains("COLOR_0"));
  const nlohmann::json& accessor =
      glb.gltf["accessors"][primitive["attributes"]["COLOR_0"].get<size_t>()];
  EXPECT_EQ(accessor["count"], 4);
  EXPECT_EQ(accessor["type"], "VEC4");
  EXPECT_EQ(accessor["componentType"], 5121);  // unsigned byte
  EXPECT_EQ(accessor["normalized"], true);

  const nlohmann::json& view = glb.gltf["bufferViews"][accessor["bufferView"].get<size_t>()];
  const size_t stride = view.value("byteStride", size_t{4});
  const size_t start =
      view.value("byteOffset", size_t{0}) + accessor.value("byteOffset", size_t{0});
  const auto colour_of = [&](size_t vertex) {
    const size_t at = start + vertex * stride;
    EXPECT_LE(at + 4, glb.bin.size());
    std::vector<uint8_t> rgba(4);
    std::memcpy(rgba.data(), glb.bin.data() + at, 4);
    return rgba;
  };
  EXPECT_EQ(colour_of(0), (std::vector<uint8_t>{255, 255, 255, 255}));
  EXPECT_EQ(colour_of(1), (std::vector<uint8_t>{255, 0, 0, 255}));
  EXPECT_EQ(colour_of(2), (std::vector<uint8_t>{0, 0, 255, 255}));
  EXPECT_EQ(colour_of(3), (std::vector<uint8_t>{128, 128, 128, 255}));
}

}  // namespace
}  // namespace featsense::test
