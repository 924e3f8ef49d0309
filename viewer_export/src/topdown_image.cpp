#include "featsense/viewer_export/topdown_image.hpp"

#include <zlib.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <vector>

namespace featsense::viewer_export {
namespace {

/// A perceptually even blue-green-yellow ramp (control points of matplotlib's viridis,
/// interpolated linearly), t in [0, 1].
std::array<double, 3> height_colour(double t) {
  static const double kStops[][3] = {
      {0.267, 0.005, 0.329}, {0.283, 0.141, 0.458}, {0.254, 0.265, 0.530}, {0.207, 0.372, 0.553},
      {0.164, 0.471, 0.558}, {0.128, 0.567, 0.551}, {0.135, 0.659, 0.518}, {0.267, 0.749, 0.441},
      {0.478, 0.821, 0.318}, {0.741, 0.873, 0.150}, {0.993, 0.906, 0.144}};
  constexpr int kSegments = 10;
  const double x = std::clamp(t, 0.0, 1.0) * kSegments;
  const int i = std::min(static_cast<int>(x), kSegments - 1);
  const double f = x - i;
  return {kStops[i][0] + f * (kStops[i + 1][0] - kStops[i][0]),
          kStops[i][1] + f * (kStops[i + 1][1] - kStops[i][1]),
          kStops[i][2] + f * (kStops[i + 1][2] - kStops[i][2])};
}

double percentile(std::vector<float> values, double q) {
  const size_t k = static_cast<size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(v >> shift));
}

void put_chunk(std::vector<uint8_t>& png, const char type[4], const std::vector<uint8_t>& data) {
  put_u32(png, static_cast<uint32_t>(data.size()));
  const size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  const uLong crc = crc32(0L, png.data() + start, static_cast<uInt>(png.size() - start));
  put_u32(png, static_cast<uint32_t>(crc));
}

/// An 8-bit RGBA PNG: every row with filter type 0, one zlib stream.
std::vector<uint8_t> encode_png(const std::vector<uint8_t>& rgba, int width, int height) {
  std::vector<uint8_t> raw;
  raw.reserve(static_cast<size_t>(height) * (static_cast<size_t>(width) * 4 + 1));
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    const auto row = rgba.begin() + static_cast<std::ptrdiff_t>(y) * width * 4;
    raw.insert(raw.end(), row, row + static_cast<std::ptrdiff_t>(width) * 4);
  }
  uLongf packed_size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<uint8_t> packed(packed_size);
  if (compress2(packed.data(), &packed_size, raw.data(), static_cast<uLong>(raw.size()), 6) != Z_OK)
    throw std::runtime_error("PNG: compression failed");
  packed.resize(packed_size);

  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<uint8_t> header;
  put_u32(header, static_cast<uint32_t>(width));
  put_u32(header, static_cast<uint32_t>(height));
  header.insert(header.end(), {8, 6, 0, 0, 0});  // 8 bits, RGBA, deflate, no filter, no interlace
  put_chunk(png, "IHDR", header);
  put_chunk(png, "IDAT", packed);
  put_chunk(png, "IEND", {});
  return png;
}

}  // namespace

TopDownImage write_topdown_png(const mesh::TriangleMesh& mesh, const std::string& path,
                               const TopDownImageSettings& settings) {
  if (mesh.triangles.empty()) throw mesh::MeshError("a top-down image needs triangles");
  mesh::validate(mesh, path);
  Eigen::AlignedBox3f box;
  std::vector<float> heights;
  heights.reserve(mesh.vertices.size());
  for (const Eigen::Vector3f& v : mesh.vertices) {
    box.extend(v);
    heights.push_back(v.z());
  }
  TopDownImage image;
  const double extent = std::max(box.sizes().x(), box.sizes().y());
  image.pixel_size_m = std::max(settings.pixel_size_m, extent / settings.max_side_px);
  image.width = std::max(1, static_cast<int>(std::ceil(box.sizes().x() / image.pixel_size_m)));
  image.height = std::max(1, static_cast<int>(std::ceil(box.sizes().y() / image.pixel_size_m)));
  image.min_x_m = box.min().x();
  image.max_y_m = box.max().y();
  image.low_z_m = percentile(heights, 0.02);
  image.high_z_m = std::max(percentile(heights, 0.98), image.low_z_m + 1e-3);

  // Per pixel the highest surface: its height and how steep it is (|n.z| of the triangle).
  const size_t pixels = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  std::vector<float> top(pixels, -std::numeric_limits<float>::infinity());
  std::vector<float> flatness(pixels, 0.0f);
  const double inv = 1.0 / image.pixel_size_m;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[static_cast<size_t>(t[0])];
    const Eigen::Vector3f& b = mesh.vertices[static_cast<size_t>(t[1])];
    const Eigen::Vector3f& c = mesh.vertices[static_cast<size_t>(t[2])];
    const Eigen::Vector3f normal = (b - a).cross(c - a);
    const float length = normal.norm();
    if (!(length > 0.0f)) continue;
    const float nz = std::abs(normal.z()) / length;
    // Pixel coordinates: x to the right, y down from the top edge.
    const double px[3] = {(a.x() - image.min_x_m) * inv, (b.x() - image.min_x_m) * inv,
                          (c.x() - image.min_x_m) * inv};
    const double py[3] = {(image.max_y_m - a.y()) * inv, (image.max_y_m - b.y()) * inv,
                          (image.max_y_m - c.y()) * inv};
    const double area = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({px[0], px[1], px[2]}))));
    const int x1 =
        std::min(image.width - 1, static_cast<int>(std::floor(std::max({px[0], px[1], px[2]}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({py[0], py[1], py[2]}))));
    const int y1 =
        std::min(image.height - 1, static_cast<int>(std::floor(std::max({py[0], py[1], py[2]}))));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double cx = x + 0.5;
        const double cy = y + 0.5;
        double z;
        if (std::abs(area) < 1e-12) {
          // Seen edge-on (a wall): it covers the pixels its outline touches, at its top.
          z = std::max({a.z(), b.z(), c.z()});
        } else {
          const double w0 = ((px[1] - cx) * (py[2] - cy) - (px[2] - cx) * (py[1] - cy)) / area;
          const double w1 = ((px[2] - cx) * (py[0] - cy) - (px[0] - cx) * (py[2] - cy)) / area;
          const double w2 = 1.0 - w0 - w1;
          if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
          z = w0 * a.z() + w1 * b.z() + w2 * c.z();
        }
        const size_t i =
            static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x);
        if (z > top[i]) {
          top[i] = static_cast<float>(z);
          flatness[i] = nz;
        }
      }
    }
  }

  std::vector<uint8_t> rgba(pixels * 4, 0);
  for (size_t i = 0; i < pixels; ++i) {
    if (!std::isfinite(top[i])) continue;  // nothing there: transparent
    const std::array<double, 3> colour =
        height_colour((top[i] - image.low_z_m) / (image.high_z_m - image.low_z_m));
    // Steep faces (walls seen from above) darker, so structures stand out from the floor.
    const double shade = 0.55 + 0.45 * flatness[i];
    for (int k = 0; k < 3; ++k) {
      rgba[4 * i + static_cast<size_t>(k)] = static_cast<uint8_t>(
          std::lround(255.0 * std::clamp(colour[static_cast<size_t>(k)] * shade, 0.0, 1.0)));
    }
    rgba[4 * i + 3] = 255;
  }
  const std::vector<uint8_t> png = encode_png(rgba, image.width, image.height);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  if (!out.flush()) throw std::runtime_error("cannot write " + path);
  return image;
}

}  // namespace featsense::viewer_export
