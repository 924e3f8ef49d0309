// The plan view (topdown.png) on analytic scenes: the ceiling cut away, walls dark, a door a
// gap, the path drawn; a cut that follows the path from storey to storey; the grid's spacing;
// the PNG as a viewer decodes it (here with zlib).

#include <gtest/gtest.h>
#include <zlib.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/viewer_export/plan_view.hpp"

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

using V = Eigen::Vector3f;

/// A room of 10 x 8 m (x, y from 0), 3 m high, with its ceiling; a door 1 m wide and 2.1 m
/// high in the east wall (x = 10, y 3.5 to 4.5) onto a landing outside (x 10 to 13); a pillar
/// (x 3 to 3.6, y 5 to 5.6) and a table 0.75 m high (x 6 to 7.5, y 5.5 to 6.5). Floors face
/// up, the ceiling down.
mesh::TriangleMesh room() {
  mesh::TriangleMesh m;
  const uint32_t part = m.add_part("room", 0.5f);
  const auto wall_x = [&](float x, float y0, float y1, float z0, float z1) {
    m.add_quad(V(x, y0, z0), V(x, y1, z0), V(x, y1, z1), V(x, y0, z1), part);
  };
  const auto wall_y = [&](float y, float x0, float x1, float z0, float z1) {
    m.add_quad(V(x0, y, z0), V(x1, y, z0), V(x1, y, z1), V(x0, y, z1), part);
  };
  const auto level = [&](float x0, float y0, float x1, float y1, float z, bool up) {
    if (up) {
      m.add_quad(V(x0, y0, z), V(x1, y0, z), V(x1, y1, z), V(x0, y1, z), part);
    } else {
      m.add_quad(V(x0, y0, z), V(x0, y1, z), V(x1, y1, z), V(x1, y0, z), part);
    }
  };
  level(0, 0, 10, 8, 0, true);
  level(10, 3, 13, 5, 0, true);
  level(0, 0, 10, 8, 3, false);
  wall_y(0, 0, 10, 0, 3);
  wall_y(8, 0, 10, 0, 3);
  wall_x(0, 0, 8, 0, 3);
  wall_x(10, 0, 3.5f, 0, 3);
  wall_x(10, 4.5f, 8, 0, 3);
  wall_x(10, 3.5f, 4.5f, 2.1f, 3);  // over the door
  wall_x(3, 5, 5.6f, 0, 3);
  wall_x(3.6f, 5, 5.6f, 0, 3);
  wall_y(5, 3, 3.6f, 0, 3);
  wall_y(5.6f, 3, 3.6f, 0, 3);
  level(6, 5.5f, 7.5f, 6.5f, 0.75f, true);
  wall_x(6, 5.5f, 6.5f, 0, 0.75f);
  wall_x(7.5f, 5.5f, 6.5f, 0, 0.75f);
  wall_y(5.5f, 6, 7.5f, 0, 0.75f);
  wall_y(6.5f, 6, 7.5f, 0, 0.75f);
  return m;
}

/// Positions every 10 cm along straight legs through `corners`.
std::vector<Eigen::Vector3d> walk(const std::vector<Eigen::Vector3d>& corners) {
  std::vector<Eigen::Vector3d> positions;
  for (size_t k = 0; k + 1 < corners.size(); ++k) {
    const int steps = static_cast<int>(std::ceil((corners[k + 1] - corners[k]).norm() / 0.1));
    for (int s = 0; s < steps; ++s)
      positions.push_back(corners[k] + (corners[k + 1] - corners[k]) * s / steps);
  }
  positions.push_back(corners.back());
  return positions;
}

/// A sensor carried at 1.5 m through the room and out of its door.
PlanPath path_through_room() {
  PlanPath path;
  path.label = "estimate";
  path.positions_m = walk({{2, 2, 1.5}, {8, 2, 1.5}, {8, 4, 1.5}, {12.5, 4, 1.5}});
  return path;
}

/// Pixels of the plan by map coordinates.
struct Plan {
  PlanImage image;
  int column(double x) const {
    return static_cast<int>(std::floor((x - image.view.min_x_m) / image.view.pixel_size_m));
  }
  int row(double y) const {
    return static_cast<int>(std::floor((image.view.max_y_m - y) / image.view.pixel_size_m));
  }
  size_t index(int column, int row) const {
    return static_cast<size_t>(row) * static_cast<size_t>(image.view.width_px) +
           static_cast<size_t>(column);
  }
  float height(double x, double y) const {
    return image.surface_height_m[index(column(x), row(y))];
  }
  const unsigned char* rgba(double x, double y) const {
    return &image.rgba[4 * index(column(x), row(y))];
  }
  /// A wall's line: some pixel within one of (x, y) is near black.
  bool dark_near(double x, double y) const {
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        const unsigned char* p = &image.rgba[4 * index(column(x) + dc, row(y) + dr)];
        if (p[0] < 80 && p[1] < 80 && p[2] < 80) return true;
      }
    }
    return false;
  }
};

bool is_red(const unsigned char* p) { return p[0] > 150 && p[1] < 100 && p[2] < 100; }
bool is_light(const unsigned char* p) { return p[0] > 150 && p[1] > 150 && p[2] > 150; }

PlanViewSettings fixed_pixels() {
  PlanViewSettings settings;
  settings.pixel_size_m = 0.05;
  settings.min_side_px = 1;  // the pixel size as set
  return settings;
}

TEST(PlanView, ARoomShowsItsFloorWallsPillarDoorAndPath) {
  const Plan plan{render_plan_view(room(), {path_through_room()}, fixed_pixels())};
  const PlanView& view = plan.image.view;
  EXPECT_NEAR(view.pixel_size_m, 0.05, 1e-12);
  // Everywhere the path is within reach: 0.3 m above the sensor, below the door's top.
  EXPECT_NEAR(view.cut_low_m, 1.8, 1e-6);
  EXPECT_NEAR(view.cut_high_m, 1.8, 1e-6);
  // The floor, not the ceiling, in the room's free corners, light and not a wall.
  for (const auto& [x, y] : {std::pair{1.0, 7.0}, std::pair{9.0, 7.0}, std::pair{5.0, 4.0}}) {
    EXPECT_NEAR(plan.height(x, y), 0.0, 1e-4) << x << ", " << y;
    EXPECT_TRUE(is_light(plan.rgba(x, y))) << x << ", " << y;
  }
  // Walls, cut at 1.8 m, as dark lines, and so is the pillar's outline.
  EXPECT_TRUE(plan.dark_near(0.0, 5.0));
  EXPECT_TRUE(plan.dark_near(5.0, 8.0));
  EXPECT_TRUE(plan.dark_near(10.0, 6.0));
  EXPECT_TRUE(plan.dark_near(3.0, 5.3));
  EXPECT_TRUE(plan.dark_near(3.3, 5.6));
  EXPECT_NEAR(plan.height(0.0, 5.0), 1.8, 1e-3);
  EXPECT_FALSE(plan.dark_near(2.0, 5.3));
  // The door is a gap: the floor shows through, at the floor's height.
  EXPECT_NEAR(plan.height(10.0, 3.8), 0.0, 1e-4);
  EXPECT_FALSE(plan.dark_near(10.0, 3.8));
  // The table's top at its height, a different colour from the floor's.
  EXPECT_NEAR(plan.height(6.75, 6.0), 0.75, 1e-4);
  const unsigned char* floor = plan.rgba(5.0, 7.0);
  const unsigned char* table = plan.rgba(6.75, 6.0);
  EXPECT_GT(
      std::abs(floor[0] - table[0]) + std::abs(floor[1] - table[1]) + std::abs(floor[2] - table[2]),
      30);
  // The path, in the estimate's red, through the room and the door.
  EXPECT_TRUE(is_red(plan.rgba(5.0, 2.0)));
  EXPECT_TRUE(is_red(plan.rgba(8.0, 3.0)));
  EXPECT_TRUE(is_red(plan.rgba(10.0, 4.0)));
  EXPECT_FALSE(is_red(plan.rgba(5.0, 6.0)));
}

TEST(PlanView, TheTruthIsDrawnBlueBesideTheEstimate) {
  PlanPath truth = path_through_room();
  truth.kind = PlanPath::Kind::kTruth;
  truth.label = "truth";
  for (Eigen::Vector3d& p : truth.positions_m) p.y() -= 0.5;
  const Plan plan{render_plan_view(room(), {path_through_room(), truth}, fixed_pixels())};
  const unsigned char* blue = plan.rgba(5.0, 1.5);
  EXPECT_GT(blue[2], 150);
  EXPECT_LT(blue[0], 100);
  EXPECT_TRUE(is_red(plan.rgba(5.0, 2.0)));
}

// A localizer's path: red where localized, amber where on odometry, a gap where lost (a
// non-finite position), with no line across it.
TEST(PlanView, AGapInAPathIsLeftOpenAndUncertainStretchesAreAmber) {
  const Eigen::Vector3d gap = Eigen::Vector3d::Constant(std::nan(""));
  PlanPath localized;
  localized.label = "localized";
  localized.positions_m = {{1, 2, 1.5}, {3, 2, 1.5}, gap, gap, {7, 2, 1.5}, {9, 2, 1.5}};
  PlanPath odometry;
  odometry.kind = PlanPath::Kind::kUncertain;
  odometry.label = "on odometry";
  odometry.positions_m = {gap, gap, gap, gap, gap, gap, {9, 2, 1.5}, {9, 6, 1.5}};
  const Plan plan{render_plan_view(room(), {localized, odometry}, fixed_pixels())};
  EXPECT_TRUE(is_red(plan.rgba(2.0, 2.0)));
  EXPECT_TRUE(is_red(plan.rgba(8.0, 2.0)));
  EXPECT_FALSE(is_red(plan.rgba(5.0, 2.0)));  // lost between 3 and 7 m
  const unsigned char* amber = plan.rgba(9.0, 4.0);
  EXPECT_GT(amber[0], 200);
  EXPECT_GT(amber[1], 120);
  EXPECT_LT(amber[2], 80);
}

// Surfaces in their vertices' colours (mesh_error.png): the room's floor, in the colour its
// vertices carry, where the height ramp would be; its walls too; the cut and the path as ever.
TEST(PlanView, VertexColoursReplaceTheHeightColours) {
  const mesh::TriangleMesh mesh = room();
  PlanVertexColours colours;
  colours.rgb.assign(mesh.vertices.size(), Eigen::Matrix<uint8_t, 3, 1>(40, 200, 60));
  // The table's top in blue: the vertices at its height (its top, its sides' upper edges).
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (std::abs(mesh.vertices[v].z() - 0.75f) < 1e-6f) colours.rgb[v] = {20, 20, 230};
  }
  colours.low = "low";
  colours.high = "high";
  colours.ramp = [](double t) {
    const auto level = static_cast<uint8_t>(std::lround(255.0 * t));
    return std::array<uint8_t, 3>{level, level, level};
  };
  const Plan plan{render_plan_view(mesh, {path_through_room()}, fixed_pixels(), &colours)};
  // Off the grid's lines; level, so lit as it is.
  const unsigned char* floor = plan.rgba(5.5, 7.5);
  EXPECT_EQ(floor[0], 40);
  EXPECT_EQ(floor[1], 200);
  EXPECT_EQ(floor[2], 60);
  const unsigned char* table = plan.rgba(6.7, 6.3);
  EXPECT_GT(table[2], 150);
  EXPECT_LT(table[0], 50);
  const unsigned char* wall = plan.rgba(0.0, 5.0);
  EXPECT_GT(wall[1], wall[0] + 50) << "a wall keeps its vertices' green";
  EXPECT_NEAR(plan.image.view.cut_low_m, 1.8, 1e-6);
  EXPECT_TRUE(is_red(plan.rgba(5.0, 2.0)));

  colours.rgb.pop_back();
  EXPECT_THROW(render_plan_view(mesh, {}, fixed_pixels(), &colours), mesh::MeshError);
}

TEST(PlanView, AFixedCutHeightOverridesThePath) {
  PlanViewSettings settings = fixed_pixels();
  settings.cut_height_m = 0.5;  // below the table's top
  const Plan plan{render_plan_view(room(), {path_through_room()}, settings)};
  EXPECT_EQ(plan.image.view.cut_low_m, 0.5);
  EXPECT_NEAR(plan.height(6.75, 6.0), 0.0, 1e-4);
  EXPECT_NE(plan.image.view.cut_rule.find("fixed"), std::string::npos);
}

TEST(PlanView, WithoutAPathItCutsBetweenFloorAndCeiling) {
  const Plan plan{render_plan_view(room(), {}, fixed_pixels())};
  // 1.5 m above the floor: below the ceiling at 3 m, which half the storey would be too.
  EXPECT_NEAR(plan.image.view.cut_low_m, 1.5, 1e-6);
  EXPECT_NEAR(plan.height(5.0, 4.0), 0.0, 1e-4);
  EXPECT_TRUE(plan.dark_near(0.0, 5.0));
  EXPECT_NE(plan.image.view.cut_rule.find("no path"), std::string::npos);
}

TEST(PlanView, WithoutPathOrCeilingNothingIsCut) {
  mesh::TriangleMesh ground;
  const uint32_t part = ground.add_part("ground", 0.5f);
  ground.add_quad(V(0, 0, 0), V(20, 0, 0), V(20, 20, 0), V(0, 20, 0), part);
  ground.add_quad(V(5, 5, 8), V(8, 5, 8), V(8, 8, 8), V(5, 8, 8), part);  // a roof, seen
  const Plan plan{render_plan_view(ground, {}, fixed_pixels())};
  EXPECT_TRUE(std::isinf(plan.image.view.cut_high_m));
  EXPECT_NEAR(plan.height(6.0, 6.0), 8.0, 1e-4);
}

/// Two storeys side by side on one ground floor: the west half (x 0 to 20) one storey high
/// (ceiling at 3 m), the east half (x 20 to 40) with a floor at 3.2 m and a roof at 6 m. The
/// path walks the west half on the ground and the east half upstairs.
TEST(PlanView, TheCutFollowsThePathFromStoreyToStorey) {
  mesh::TriangleMesh m;
  const uint32_t part = m.add_part("building", 0.5f);
  m.add_quad(V(0, 0, 0), V(40, 0, 0), V(40, 10, 0), V(0, 10, 0), part);  // ground floor
  m.add_quad(V(0, 0, 3), V(0, 10, 3), V(40, 10, 3), V(40, 0, 3), part);  // its ceiling
  m.add_quad(V(20, 0, 3.2f), V(40, 0, 3.2f), V(40, 10, 3.2f), V(20, 10, 3.2f), part);  // upstairs
  m.add_quad(V(20, 0, 6), V(20, 10, 6), V(40, 10, 6), V(40, 0, 6), part);              // roof
  PlanPath downstairs;
  downstairs.positions_m = walk({{2, 5, 1.5}, {12, 5, 1.5}});
  PlanPath upstairs;
  upstairs.positions_m = walk({{28, 5, 4.7}, {38, 5, 4.7}});
  const Plan plan{render_plan_view(m, {downstairs, upstairs}, fixed_pixels())};
  EXPECT_NEAR(plan.image.view.cut_low_m, 1.8, 1e-6);
  EXPECT_NEAR(plan.image.view.cut_high_m, 5.0, 1e-6);
  EXPECT_NEAR(plan.height(6.0, 8.0), 0.0, 1e-4);   // downstairs: the ground floor
  EXPECT_NEAR(plan.height(34.0, 8.0), 3.2, 1e-4);  // upstairs: its floor, not the roof
  // One cut for all would show the west half's ceiling or the east half's ground floor.
  PlanViewSettings one_cut = fixed_pixels();
  one_cut.cut_height_m = 5.0;
  EXPECT_NEAR(Plan{render_plan_view(m, {downstairs, upstairs}, one_cut)}.height(6.0, 8.0), 3.0,
              1e-4);
}

TEST(PlanView, GridSpacingIsOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(plan_grid_spacing_m(37.0), 5.0);
  EXPECT_DOUBLE_EQ(plan_grid_spacing_m(400.0), 50.0);
  EXPECT_DOUBLE_EQ(plan_grid_spacing_m(100.0), 10.0);
  EXPECT_DOUBLE_EQ(plan_grid_spacing_m(15.0), 2.0);
  EXPECT_NEAR(plan_grid_spacing_m(3.0), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(plan_grid_spacing_m(12000.0), 2000.0);
  EXPECT_DOUBLE_EQ(plan_grid_spacing_m(0.0), 1.0);
}

TEST(PlanView, LargeMapsGetLargerPixels) {
  mesh::TriangleMesh m = room();
  for (Eigen::Vector3f& v : m.vertices) v.head<2>() *= 500.0f;  // 6.5 x 4 km
  PlanViewSettings settings;
  settings.max_side_px = 500;
  const PlanView view = render_plan_view(m, {}, settings).view;
  EXPECT_EQ(view.width_px, 500);
  EXPECT_GT(view.pixel_size_m, 13.0);
  EXPECT_EQ(view.grid_spacing_m, 1000.0);
}

TEST(PlanView, SmallMapsGetFinerPixels) {
  const PlanView view = render_plan_view(room(), {path_through_room()}).view;
  EXPECT_LT(view.pixel_size_m, 0.05);
  EXPECT_GE(view.width_px, 800);
}

TEST(PlanView, ThePngHoldsTheRenderedPixels) {
  const auto dir = test::scratch_dir("plan_view");
  const std::string path = (dir / "topdown.png").string();
  const PlanImage image = render_plan_view(room(), {path_through_room()}, fixed_pixels());
  const PlanView view = write_plan_view_png(room(), {path_through_room()}, path, fixed_pixels());
  EXPECT_EQ(view.width_px, image.view.width_px);
  const DecodedPng png = decode(path);
  ASSERT_EQ(png.width, static_cast<uint32_t>(view.width_px));
  ASSERT_EQ(png.height, static_cast<uint32_t>(view.height_px));
  EXPECT_EQ(png.rgba, image.rgba);
}

TEST(PlanView, AMeshWithoutTrianglesIsAnError) {
  mesh::TriangleMesh points;
  points.vertices.push_back({0, 0, 0});
  EXPECT_THROW(write_plan_view_png(points, {}, "/nonexistent/top.png"), mesh::MeshError);
}

TEST(PlanView, AnUnwritablePathIsAnError) {
  EXPECT_THROW(write_plan_view_png(room(), {}, "/nonexistent/folder/top.png", fixed_pixels()),
               std::runtime_error);
}

}  // namespace
}  // namespace featsense::viewer_export
