// The top-down quick look: a PNG that a viewer opens (decoded here with zlib), north up,
// higher surfaces in later colours of the ramp, and nothing where the mesh has nothing.

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/viewer_export/topdown_image.hpp"

namespace featsense::viewer_export {
namespace {

struct DecodedPng {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> rgba;
  const uint8_t* pixel(uint32_t x, uint32_t y) const { return &rgba[(y * width + x) * 4]; }
};

uint32_t read_u32(const std::vector<uint8_t>& b, size_t at) {
  return (uint32_t{b[at]} << 24) | (uint32_t{b[at + 1]} << 16) | (uint32_t{b[at + 2]} << 8) |
         b[at + 3];
}

/// A minimal decoder for what the writer makes: 8-bit RGBA, filter 0 rows, checked CRCs.
DecodedPng decode(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> b((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
  const std::vector<uint8_t> signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  EXPECT_TRUE(std::equal(signature.begin(), signature.end(), b.begin()));
  DecodedPng png;
  std::vector<uint8_t> idat;
  for (size_t at = 8; at + 12 <= b.size();) {
    const uint32_t length = read_u32(b, at);
    const std::string type(b.begin() + static_cast<std::ptrdiff_t>(at + 4),
                           b.begin() + static_cast<std::ptrdiff_t>(at + 8));
    const uLong crc = crc32(0L, b.data() + at + 4, length + 4);
    EXPECT_EQ(read_u32(b, at + 8 + length), crc) << type;
    if (type == "IHDR") {
      png.width = read_u32(b, at + 8);
      png.height = read_u32(b, at + 12);
      EXPECT_EQ(b[at + 16], 8);  // bit depth
      EXPECT_EQ(b[at + 17], 6);  // RGBA
    } else if (type == "IDAT") {
      idat.insert(idat.end(), b.begin() + static_cast<std::ptrdiff_t>(at + 8),
                  b.begin() + static_cast<std::ptrdiff_t>(at + 8 + length));
    }
    at += 12 + length;
  }
  std::vector<uint8_t> raw(static_cast<size_t>(png.height) * (png.width * 4 + 1));
  uLongf raw_size = raw.size();
  EXPECT_EQ(uncompress(raw.data(), &raw_size, idat.data(), idat.size()), Z_OK);
  EXPECT_EQ(raw_size, raw.size());
  for (uint32_t y = 0; y < png.height; ++y) {
    const uint8_t* row = raw.data() + y * (png.width * 4 + 1);
    EXPECT_EQ(row[0], 0) << "filter of row " << y;
    png.rgba.insert(png.rgba.end(), row + 1, row + 1 + png.width * 4);
  }
  return png;
}

/// A 4 x 4 m floor at z = 0 (west half) and a 2 x 4 m platform at z = 2 (north-east
/// quarter), 1 m apart, so the image has an empty strip between them.
mesh::TriangleMesh two_levels() {
  mesh::TriangleMesh m;
  const auto quad = [&](float x0, float y0, float x1, float y1, float z) {
    const int base = static_cast<int>(m.vertices.size());
    m.vertices.push_back({x0, y0, z});
    m.vertices.push_back({x1, y0, z});
    m.vertices.push_back({x1, y1, z});
    m.vertices.push_back({x0, y1, z});
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
  };
  quad(0, 0, 2, 4, 0);
  quad(3, 2, 5, 4, 2);
  return m;
}

TEST(TopDownImage, HeightsBecomeColoursNorthUp) {
  const auto dir = test::scratch_dir("topdown");
  const std::string path = (dir / "top.png").string();
  TopDownImageSettings settings;
  settings.pixel_size_m = 0.1;
  const TopDownImage info = write_topdown_png(two_levels(), path, settings);
  EXPECT_EQ(info.width, 50);
  EXPECT_EQ(info.height, 40);
  const DecodedPng png = decode(path);
  ASSERT_EQ(png.width, 50u);
  ASSERT_EQ(png.height, 40u);
  const uint8_t* floor = png.pixel(10, 20);       // x = 1.05 m, y = 1.95 m
  const uint8_t* platform = png.pixel(40, 5);     // x = 4.05 m, y = 3.45 m: north is up
  const uint8_t* gap = png.pixel(25, 20);         // x = 2.55 m: nothing there
  const uint8_t* south_east = png.pixel(40, 35);  // below the platform: nothing
  EXPECT_EQ(floor[3], 255);
  EXPECT_EQ(platform[3], 255);
  EXPECT_EQ(gap[3], 0);
  EXPECT_EQ(south_east[3], 0);
  // The ramp runs from purple (low) to yellow (high).
  EXPECT_GT(floor[2], floor[1]);
  EXPECT_GT(platform[0], 200);
  EXPECT_GT(platform[1], 200);
  EXPECT_LT(platform[2], 80);
}

TEST(TopDownImage, LargeMapsGetLargerPixels) {
  mesh::TriangleMesh m = two_levels();
  for (Eigen::Vector3f& v : m.vertices) v.head<2>() *= 1000.0f;  // 5 x 4 km
  const auto dir = test::scratch_dir("topdown_large");
  TopDownImageSettings settings;
  settings.max_side_px = 500;
  const TopDownImage info = write_topdown_png(m, (dir / "top.png").string(), settings);
  EXPECT_EQ(info.width, 500);
  EXPECT_NEAR(info.pixel_size_m, 10.0, 1e-9);
}

TEST(TopDownImage, AMeshWithoutTrianglesIsAnError) {
  mesh::TriangleMesh points;
  points.vertices.push_back({0, 0, 0});
  EXPECT_THROW(write_topdown_png(points, "/nonexistent/top.png"), mesh::MeshError);
}

}  // namespace
}  // namespace featsense::viewer_export
