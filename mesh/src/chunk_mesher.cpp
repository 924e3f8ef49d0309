#include "internal/chunk_mesher.hpp"

#include <algorithm>
#include <array>
#include <cstring>

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

/// Per-thread tables, reused chunk after chunk.
struct MarchingScratch {
  /// Vertex index per cube edge of the chunk, reset entry by entry: a chunk touches few of
  /// its 824,000 edges, and clearing them all would cost more than meshing.
  std::vector<int32_t> slots =
      std::vector<int32_t>(static_cast<std::size_t>(kCorners) * kCorners * kCorners * 3, -1);
  std::vector<std::size_t> touched;
  /// Per row of corners (y, z in 0 .. 64), observed voxels as bit masks (x = 0 .. 63) of
  /// negative and of not negative values, and the same two bits for x = 64 (bits 0 and 1).
  std::vector<uint64_t> negative = std::vector<uint64_t>(kCorners * kCorners);
  std::vector<uint64_t> positive = std::vector<uint64_t>(kCorners * kCorners);
  std::vector<uint8_t> last = std::vector<uint8_t>(kCorners * kCorners);
};

/// 64 bytes of 0 or 1 as the bits of a word (byte i to bit i). Each multiplication gathers
/// eight bytes, read as a little-endian word, into its top byte.
inline uint64_t pack_bits(const std::array<uint8_t, storage::kChunkSize>& bytes) {
  uint64_t packed = 0;
  for (std::size_t k = 0; k < bytes.size() / 8; ++k) {
    uint64_t word = 0;
    std::memcpy(&word, bytes.data() + 8 * k, sizeof(word));
    packed |= ((word * 0x0102040810204080ull) >> 56) << (8 * k);
  }
  return packed;
}

class CubeMarcher {
 public:
  CubeMarcher(const PaddedBlock& block, const ChunkMeshingParameters& parameters,
              MarchingScratch& scratch, ChunkMesh& out)
      : voxels_(block.voxels),
        key_(block.key),
        parameters_(parameters),
        scratch_(scratch),
        out_(out) {}

  ~CubeMarcher() {
    for (const std::size_t slot : scratch_.touched) scratch_.slots[slot] = -1;
    scratch_.touched.clear();
  }
  CubeMarcher(const CubeMarcher&) = delete;
  CubeMarcher& operator=(const CubeMarcher&) = delete;

  void run() {
    mask_rows();
    const tsdf::Index3 begin = parameters_.cube_begin;
    const tsdf::Index3 end = parameters_.cube_end;
    for (int32_t bz = begin.z; bz < end.z; bz += kBlockCubes)
      for (int32_t by = begin.y; by < end.y; by += kBlockCubes)
        for (int32_t bx = begin.x; bx < end.x; bx += kBlockCubes) {
          const tsdf::Index3 lo{bx, by, bz};
          const tsdf::Index3 hi{std::min(bx + kBlockCubes, end.x),
                                std::min(by + kBlockCubes, end.y),
                                std::min(bz + kBlockCubes, end.z)};
          if (has_sign_change(lo, hi)) march_block(lo, hi);
        }
  }

 private:
  static std::size_t row_index(int32_t y, int32_t z) {
    return static_cast<std::size_t>(y + kCorners * z);
  }

  /// Builds the row masks of the scratch (an observed voxel has bits >= min_weight << 16).
  /// Whole rows of cubes are then tested with a few bit operations.
  void mask_rows() {
    const uint32_t observed_from = parameters_.min_weight_fixed << 16;
    for (int32_t z = 0; z < kCorners; ++z)
      for (int32_t y = 0; y < kCorners; ++y) {
        const uint32_t* row = voxels_.data() + PaddedBlock::index(0, y, z);
        // One byte per voxel first (a loop the compiler vectorises), then eight bytes to
        // eight bits at a time.
        std::array<uint8_t, storage::kChunkSize> negative_bytes{};
        std::array<uint8_t, storage::kChunkSize> positive_bytes{};
        for (int32_t x = 0; x < storage::kChunkSize; ++x) {
          const uint32_t bits = row[x];
          const uint32_t observed = bits >= observed_from ? 1u : 0u;
          const uint32_t sign = (bits >> 15) & 1u;
          negative_bytes[static_cast<size_t>(x)] = static_cast<uint8_t>(observed & sign);
          positive_bytes[static_cast<size_t>(x)] = static_cast<uint8_t>(observed & (sign ^ 1u));
        }
        const uint64_t negative = pack_bits(negative_bytes);
        const uint64_t positive = pack_bits(positive_bytes);
        const uint32_t last = row[storage::kChunkSize];
        const uint32_t last_observed = last >= observed_from ? 1u : 0u;
        const uint32_t last_sign = (last >> 15) & 1u;
        const std::size_t r = row_index(y, z);
        scratch_.negative[r] = negative;
        scratch_.positive[r] = positive;
        scratch_.last[r] = static_cast<uint8_t>((last_observed & last_sign) |
                                                ((last_observed & (last_sign ^ 1u)) << 1));
      }
  }

  /// Corners x .. x + 8 of row r as bits 0 .. 8: negative ones (negative = true) or not.
  uint32_t segment(std::size_t r, int32_t x, bool negative) const {
    uint64_t bits = (negative ? scratch_.negative[r] : scratch_.positive[r]) >> x;
    if (x + 9 > 64) {
      const uint64_t last = (scratch_.last[r] >> (negative ? 0 : 1)) & 1u;
      bits |= last << (64 - x);
    }
    return static_cast<uint32_t>(bits & 0x1FFu);
  }

  /// Whether observed corners of the cubes [lo, hi) have both signs; most blocks have not.
  bool has_sign_change(tsdf::Index3 lo, tsdf::Index3 hi) const {
    uint32_t negative = 0;
    uint32_t positive = 0;
    for (int32_t z = lo.z; z <= hi.z; ++z)
      for (int32_t y = lo.y; y <= hi.y; ++y) {
        const std::size_t r = row_index(y, z);
        negative |= segment(r, lo.x, true);
        positive |= segment(r, lo.x, false);
      }
    const uint32_t corners = (2u << static_cast<uint32_t>(hi.x - lo.x)) - 1u;
    return (negative & corners) != 0u && (positive & corners) != 0u;
  }

  /// Marches the cubes that can have faces, found a row of cubes at a time from the masks of
  /// their four corner rows: some corner negative, some not, all observed.
  void march_block(tsdf::Index3 lo, tsdf::Index3 hi) {
    const auto& cases = cube_cases();
    const uint32_t row_cubes = (1u << static_cast<uint32_t>(hi.x - lo.x)) - 1u;
    for (int32_t z = lo.z; z < hi.z; ++z)
      for (int32_t y = lo.y; y < hi.y; ++y) {
        std::array<uint32_t, 4> negative_rows{};  // corner row (y + dy, z + dz) at dy + 2 dz
        uint32_t negative = 0;
        uint32_t positive = 0;
        uint32_t observed = 0x1FFu;
        for (int k = 0; k < 4; ++k) {
          const std::size_t r = row_index(y + (k & 1), z + (k >> 1));
          const uint32_t n = segment(r, lo.x, true);
          const uint32_t p = segment(r, lo.x, false);
          negative_rows[static_cast<size_t>(k)] = n;
          negative |= n;
          positive |= p;
          observed &= n | p;
        }
        // Cube x spans corners x and x + 1.
        uint32_t candidates = (negative | (negative >> 1)) & (positive | (positive >> 1)) &
                              observed & (observed >> 1) & row_cubes;
        while (candidates != 0u) {
          const int lx = __builtin_ctz(candidates);
          candidates &= candidates - 1u;
          // Corner c = dx + 2 dy + 4 dz: bit dx of corner row dy + 2 dz.
          int case_bits = 0;
          for (int k = 0; k < 4; ++k) {
            const auto pair = static_cast<int>((negative_rows[static_cast<size_t>(k)] >> lx) & 3u);
            case_bits |= (pair & 1) << (2 * k);
            case_bits |= (pair >> 1) << (2 * k + 1);
          }
          const int32_t x = lo.x + lx;
          const CubeCase& cube_case = cases[static_cast<size_t>(case_bits)];
          for (int t = 0; t < cube_case.triangle_count; ++t) {
            const auto& edges = cube_case.triangles[static_cast<size_t>(t)];
            out_.triangles.emplace_back(vertex(x, y, z, edges[0]), vertex(x, y, z, edges[1]),
                                        vertex(x, y, z, edges[2]));
          }
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
    if (scratch_.slots[slot] >= 0) return scratch_.slots[slot];
    const auto index = static_cast<int32_t>(out_.vertices.size());
    scratch_.slots[slot] = index;
    scratch_.touched.push_back(slot);
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
  MarchingScratch& scratch_;
  ChunkMesh& out_;
};

}  // namespace

ChunkMesh mesh_chunk(const PaddedBlock& block, const ChunkMeshingParameters& parameters) {
  thread_local MarchingScratch scratch;
  ChunkMesh out;
  CubeMarcher marcher(block, parameters, scratch, out);
  marcher.run();
  return out;
}

}  // namespace featsense::mesh::internal
