#include "scene_parts.hpp"

#include "featsense/slam/sim/measurement_model.hpp"

namespace featsense::slam::scene_parts {

float draw(uint64_t stream, uint32_t a, uint32_t b, float lo, float hi) {
  return lo + (hi - lo) * static_cast<float>(hashed_uniform(0x5CE4E, stream, a, b, 0));
}

void add_wall_x(mesh::TriangleMesh& m, float x, float y0, float y1, float z0, float z1,
                uint32_t part) {
  m.add_quad(V(x, y0, z0), V(x, y1, z0), V(x, y1, z1), V(x, y0, z1), part);
}

void add_wall_y(mesh::TriangleMesh& m, float y, float x0, float x1, float z0, float z1,
                uint32_t part) {
  m.add_quad(V(x0, y, z0), V(x1, y, z0), V(x1, y, z1), V(x0, y, z1), part);
}

void add_table(mesh::TriangleMesh& m, float x0, float y0, float x1, float y1, uint32_t part) {
  m.add_box(V(x0, y0, 0.72f), V(x1, y1, 0.76f), part);
  const float leg = 0.05f;
  for (float x : {x0, x1 - leg}) {
    for (float y : {y0, y1 - leg}) m.add_box(V(x, y, 0.0f), V(x + leg, y + leg, 0.72f), part);
  }
}

void add_shelving(mesh::TriangleMesh& m, float x0, float x1, float y0, float depth, uint32_t part) {
  const float height = 2.2f;
  const float t = 0.03f;
  m.add_box(V(x0, y0, 0), V(x0 + t, y0 + depth, height), part);
  m.add_box(V(x1 - t, y0, 0), V(x1, y0 + depth, height), part);
  m.add_box(V(x0, y0 + depth - t, 0), V(x1, y0 + depth, height), part);
  for (int k = 0; k < 5; ++k) {
    const float z = 0.1f + 0.5f * static_cast<float>(k);
    m.add_box(V(x0, y0, z), V(x1, y0 + depth, z + t), part);
  }
}

void add_tree(mesh::TriangleMesh& m, float x, float y, uint32_t index, uint32_t trunk,
              uint32_t foliage, uint32_t facets) {
  m.add_cylinder(V(x, y, 0), 0.15f, 2.6f, 8, trunk);
  const V centre(x, y, 4.2f);
  const float radius = draw(1, index, 0, 1.6f, 2.2f);
  for (uint32_t k = 0; k < facets; ++k) {
    // A point in the crown's ellipsoid, then a facet of about 25 cm around it.
    V p;
    uint32_t attempt = 0;
    do {
      p = V(draw(2, index, 3 * k + attempt * 7919, -1, 1),
            draw(3, index, 3 * k + attempt * 7919, -1, 1),
            draw(4, index, 3 * k + attempt * 7919, -1, 1));
      ++attempt;
    } while (p.squaredNorm() > 1.0f && attempt < 16);
    const V at = centre + radius * V(p.x(), p.y(), 0.8f * p.z());
    V corners[3];
    for (uint32_t c = 0; c < 3; ++c) {
      corners[c] =
          at + V(draw(5, index, 3 * k + c, -0.15f, 0.15f), draw(6, index, 3 * k + c, -0.15f, 0.15f),
                 draw(7, index, 3 * k + c, -0.15f, 0.15f));
    }
    m.add_triangle(corners[0], corners[1], corners[2], foliage);
  }
}

void add_car(mesh::TriangleMesh& m, float x, float y0, uint32_t index, uint32_t tyre) {
  static const float kPaint[] = {0.04f, 0.3f, 0.55f, 0.85f, 0.2f};  // black ... white
  const uint32_t paint = m.add_part("car body", kPaint[index % 5]);
  const uint32_t glass = m.add_part("car window", Materials::kGlass);
  const float w = 1.8f;
  const float l = 4.5f;
  m.add_box(V(x, y0, 0.3f), V(x + w, y0 + l, 1.0f), paint);
  m.add_box(V(x + 0.1f, y0 + 1.2f, 1.0f), V(x + w - 0.1f, y0 + 3.6f, 1.5f), glass);
  for (float wy : {y0 + 0.6f, y0 + l - 1.3f}) {
    m.add_box(V(x - 0.02f, wy, 0), V(x + 0.25f, wy + 0.7f, 0.65f), tyre);
    m.add_box(V(x + w - 0.25f, wy, 0), V(x + w + 0.02f, wy + 0.7f, 0.65f), tyre);
  }
}

void add_light_pole(mesh::TriangleMesh& m, float x, float y, uint32_t metal) {
  m.add_cylinder(V(x, y, 0), 0.1f, 8.0f, 10, metal);
  m.add_box(V(x - 0.05f, y - 0.05f, 7.9f), V(x + 1.5f, y + 0.05f, 8.0f), metal);
  m.add_box(V(x + 1.1f, y - 0.25f, 7.7f), V(x + 1.7f, y + 0.25f, 7.9f), metal);
}

void append_placed(mesh::TriangleMesh& into, const mesh::TriangleMesh& piece, int quarter_turns,
                   const V& offset_m) {
  mesh::TriangleMesh placed = piece;
  const int turns = ((quarter_turns % 4) + 4) % 4;
  for (V& v : placed.vertices) {
    for (int k = 0; k < turns; ++k) v = V(-v.y(), v.x(), v.z());
    v += offset_m;
  }
  into.append(placed);
}

}  // namespace featsense::slam::scene_parts
