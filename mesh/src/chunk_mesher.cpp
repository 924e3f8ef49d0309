#include "internal/chunk_mesher.hpp"

#include <algorithm>
#include <array>

#include "internal/cube_cases.hpp"

namespace featsense::mesh::internal {
namespace {

constexpr int32_t kCorners = storage::kChunkSize + 1;  ///< cube corners per axis: 0 .. 64
constexpr int32_t kBlockCubes = 8;  ///< cubes per axis of the blocks that are skipped together
constexpr std::array<int32_t, 3> kStride = {1, kPaddedSize, kPaddedSize* kPaddedSize};
/// Interpolation stays this far from the voxel centres, so that a value of exactly 0 does not
/// put the vertices of several edges on one point (and their triangles to zero area).
constexpr double kMinEdgeFraction = 1e-3;

inline int32_t value_of(uint32_t bits) {
  return static_cast<int16_t>(static_cast<uint16_t>(bits & 0xFFFFu));
}
inline uint32_t weight_of(uint32_t bits) { return bits >> 16; }

/// Slot of the vertex on edge (lower voxel x, y, z in 0 .. 64, axis) in the per-thread table.
inline std::size_t vertex_slot(int32_t x, int32_t y, int32_t z, int32_t axis) {
  return (static_cast<std::size_t>(x) +
          static_cast<std::size_t>(kCorners) *
              (static_cast<std::size_t>(y) +
               static_cast<std::size_t>(kCorners) * static_cast<std::size_t>(z))) *
             3 +
         static_cast<std::size_t>(axis);
}

class CubeMarcher {
 public:
  CubeMarcher(const PaddedBlock& block, const ChunkMeshingParameters& parameters,
              std::vector<int32_t>& slots, ChunkMesh& out)
      : voxels_(block.voxels), key_(block.key), parameters_(parameters), slots_(slots), out_(out) {
    for (int c = 0; c < 8; ++c) {
      code_offset_[static_cast<size_t>(c)] = code_index(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    }
  }

  ~CubeMarcher() {
    for (const std::size_t slot : touched_) slots_[slot] = -1;  // ready for the next chunk
  }
  CubeMarcher(const CubeMarcher&) = delete;
  CubeMarcher& operator=(const CubeMarcher&) = delete;

  void run() {
    const tsdf::Index3 begin = parameters_.cube_begin;
    const tsdf::Index3 end = parameters_.cube_end;
    for (int32_t bz = begin.z; bz < end.z; bz += kBlockCubes)
      for (int32_t by = begin.y; by < end.y; by += kBlockCubes)
        for (int32_t bx = begin.x; bx < end.x; bx += kBlockCubes) {
          const tsdf::Index3 lo{bx, by, bz};
          const tsdf::Index3 hi{std::min(bx + kBlockCubes, end.x),
                                std::min(by + kBlockCubes, end.y),
                                std::min(bz + kBlockCubes, end.z)};
          if (code_corners(lo, hi)) march_block(lo, hi);
        }
  }

 private:
  /// Codes the corners of the cubes [lo, hi) (bit 0 negative, bit 1 observed) and says
  /// whether observed corners have both signs; most blocks have not. Branch-free, so that the
  /// compiler vectorises the rows: an observed voxel has bits >= min_weight << 16.
  bool code_corners(tsdf::Index3 lo, tsdf::Index3 hi) {
    const uint32_t observed_from = parameters_.min_weight_fixed << 16;
    uint32_t negative = 0;
    uint32_t positive = 0;
    const int32_t nx = hi.x - lo.x + 1;
    for (int32_t z = lo.z; z <= hi.z; ++z)
      for (int32_t y = lo.y; y <= hi.y; ++y) {
        const uint32_t* row = voxels_.data() + PaddedBlock::index(lo.x, y, z);
        uint8_t* codes = codes_.data() + code_index(0, y - lo.y, z - lo.z);
        for (int32_t x = 0; x < nx; ++x) {
          const uint32_t bits = row[x];
          const uint32_t observed = bits >= observed_from ? 1u : 0u;
          const uint32_t sign = (bits >> 15) & 1u;
          negative |= observed & sign;
          positive |= observed & (sign ^ 1u);
          codes[x] = static_cast<uint8_t>(sign | (observed << 1));
        }
      }
    return (negative & positive) != 0u;
  }

  static std::size_t code_index(int32_t x, int32_t y, int32_t z) {
    return static_cast<std::size_t>(x + (kBlockCubes + 1) * (y + (kBlockCubes + 1) * z));
  }

  void march_block(tsdf::Index3 lo, tsdf::Index3 hi) {
    const auto& cases = cube_cases();
    for (int32_t z = lo.z; z < hi.z; ++z)
      for (int32_t y = lo.y; y < hi.y; ++y)
        for (int32_t x = lo.x; x < hi.x; ++x) {
          const uint8_t* base = codes_.data() + code_index(x - lo.x, y - lo.y, z - lo.z);
          uint32_t all = 0xFFu;
          int case_bits = 0;
          for (int c = 0; c < 8; ++c) {
            const uint8_t code = base[code_offset_[static_cast<size_t>(c)]];
            all &= code;
            case_bits |= (code & 1) << c;
          }
          if ((all & 2u) == 0u || case_bits == 0 || case_bits == 255) continue;
          const CubeCase& cube_case = cases[static_cast<size_t>(case_bits)];
          for (int t = 0; t < cube_case.triangle_count; ++t) {
            const auto& edges = cube_case.triangles[static_cast<size_t>(t)];
            out_.triangles.emplace_back(vertex(x, y, z, edges[0]), vertex(x, y, z, edges[1]),
                                        vertex(x, y, z, edges[2]));
          }
        }
  }

  /// The index of the vertex on `edge` of cube (x, y, z), made on first use.
  int32_t vertex(int32_t x, int32_t y, int32_t z, int edge) {
    const int lower = edge_lower_corner(edge);
    const int32_t vx = x + (lower & 1);
    const int32_t vy = y + ((lower >> 1) & 1);
    const int32_t vz = z + ((lower >> 2) & 1);
    const int32_t axis = edge_axis(edge);
    const std::size_t slot = vertex_slot(vx, vy, vz, axis);
    if (slots_[slot] >= 0) return slots_[slot];
    const auto index = static_cast<int32_t>(out_.vertices.size());
    slots_[slot] = index;
    touched_.push_back(slot);
    make_vertex(vx, vy, vz, axis);
    const std::array<int32_t, 3> local = {vx, vy, vz};
    for (int other = 0; other < 3; ++other) {
      if (other == axis) continue;
      const int32_t coordinate = local[static_cast<size_t>(other)];
      if (coordinate == 0 || coordinate == storage::kChunkSize) {
        out_.seam_vertices.emplace_back(
            index, EdgeKey{key_.x * storage::kChunkSize + vx, key_.y * storage::kChunkSize + vy,
                           key_.z * storage::kChunkSize + vz, axis});
        break;
      }
    }
    return index;
  }

  void make_vertex(int32_t x, int32_t y, int32_t z, int32_t axis) {
    const std::size_t a = PaddedBlock::index(x, y, z);
    const std::size_t b = a + static_cast<std::size_t>(kStride[static_cast<size_t>(axis)]);
    const double va = value_of(voxels_[a]);
    const double vb = value_of(voxels_[b]);
    const double t = std::clamp(va / (va - vb), kMinEdgeFraction, 1.0 - kMinEdgeFraction);
    Eigen::Vector3d centre(key_.x * storage::kChunkSize + x + 0.5,
                           key_.y * storage::kChunkSize + y + 0.5,
                           key_.z * storage::kChunkSize + z + 0.5);
    centre[axis] += t;
    out_.vertices.push_back((centre * parameters_.voxel_size_m).cast<float>());

    Eigen::Vector3d normal = (1.0 - t) * gradient(a) + t * gradient(b);
    if (normal.squaredNorm() == 0.0) {
      // No usable neighbours at all: the edge itself says which way is positive.
      normal = (vb > va ? 1.0 : -1.0) * Eigen::Vector3d::Unit(axis);
    }
    out_.normals.push_back(normal.normalized().cast<float>());
  }

  /// TSDF gradient at a voxel (fixed-point units per voxel): central differences where both
  /// neighbours are observed, one-sided where only one is, 0 where none is.
  Eigen::Vector3d gradient(std::size_t index) const {
    Eigen::Vector3d g;
    const uint32_t min_weight = parameters_.min_weight_fixed;
    for (int axis = 0; axis < 3; ++axis) {
      const auto stride = static_cast<std::size_t>(kStride[static_cast<size_t>(axis)]);
      const uint32_t plus = voxels_[index + stride];
      const uint32_t minus = voxels_[index - stride];
      const bool has_plus = weight_of(plus) >= min_weight;
      const bool has_minus = weight_of(minus) >= min_weight;
      const double centre = value_of(voxels_[index]);
      if (has_plus && has_minus) {
        g[axis] = 0.5 * (value_of(plus) - value_of(minus));
      } else if (has_plus) {
        g[axis] = value_of(plus) - centre;
      } else if (has_minus) {
        g[axis] = centre - value_of(minus);
      } else {
        g[axis] = 0.0;
      }
    }
    return g;
  }

  const std::vector<uint32_t>& voxels_;
  storage::ChunkKey key_;
  const ChunkMeshingParameters& parameters_;
  std::vector<int32_t>& slots_;
  ChunkMesh& out_;
  std::array<std::size_t, 8> code_offset_{};
  /// Corner codes of the block being marched.
  std::array<uint8_t, (kBlockCubes + 1) * (kBlockCubes + 1) * (kBlockCubes + 1)> codes_{};
  std::vector<std::size_t> touched_;
};

}  // namespace

ChunkMesh mesh_chunk(const PaddedBlock& block, const ChunkMeshingParameters& parameters) {
  // Vertex index per cube edge of the chunk, kept per thread and reset entry by entry: a chunk
  // touches few of its 824,000 edges, and clearing them all would cost more than meshing.
  thread_local std::vector<int32_t> slots(
      static_cast<std::size_t>(kCorners) * kCorners * kCorners * 3, -1);
  ChunkMesh out;
  CubeMarcher marcher(block, parameters, slots, out);
  marcher.run();
  return out;
}

}  // namespace featsense::mesh::internal
