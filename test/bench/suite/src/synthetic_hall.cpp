#include "featsense/bench/synthetic_hall.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "featsense/tsdf/voxel.hpp"

namespace featsense::bench {
namespace {

struct Box {
  Eigen::Vector3d lo;
  Eigen::Vector3d hi;
};
struct Ball {
  Eigen::Vector3d centre;
  double radius = 0.0;
};

/// Distance to a solid box, positive outside.
double box_distance(const Eigen::Vector3d& p, const Box& box) {
  const Eigen::Vector3d q = (p - 0.5 * (box.lo + box.hi)).cwiseAbs() - 0.5 * (box.hi - box.lo);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

class Hall {
 public:
  explicit Hall(const Eigen::Vector3d& size_m)
      : inside_{Eigen::Vector3d(-0.5 * size_m.x(), -0.5 * size_m.y(), -2.0),
                Eigen::Vector3d(0.5 * size_m.x(), 0.5 * size_m.y(), size_m.z() - 2.0)} {
    const double floor = inside_.lo.z();
    // A grid of pillars, tables and crates between them, balls on the tables: surfaces of
    // every orientation, spread over the whole floor.
    for (double x = inside_.lo.x() + 4.0; x < inside_.hi.x() - 2.0; x += 8.0) {
      for (double y = inside_.lo.y() + 4.0; y < inside_.hi.y() - 2.0; y += 8.0) {
        boxes_.push_back({{x - 0.3, y - 0.3, floor}, {x + 0.3, y + 0.3, inside_.hi.z()}});
        boxes_.push_back({{x + 1.5, y + 1.0, floor + 0.7}, {x + 3.3, y + 2.0, floor + 0.78}});
        boxes_.push_back({{x - 2.7, y - 2.9, floor}, {x - 1.6, y - 1.7, floor + 1.1}});
        balls_.push_back({{x + 2.4, y + 1.5, floor + 1.13}, 0.35});
      }
    }
  }

  /// Signed distance to the nearest surface, positive in the free space of the hall.
  double distance(const Eigen::Vector3d& p) const {
    double d = -box_distance(p, inside_);  // walls, floor, ceiling
    for (const Box& box : boxes_) d = std::min(d, box_distance(p, box));
    for (const Ball& ball : balls_) d = std::min(d, (p - ball.centre).norm() - ball.radius);
    return d;
  }

  /// The hall with only the objects closer than `radius` to `centre`: the same distances
  /// wherever they are below `radius` minus the distance to `centre`, which is all a TSDF
  /// clamped at tau needs within a chunk.
  Hall near(const Eigen::Vector3d& centre, double radius) const {
    Hall out = *this;
    out.boxes_.clear();
    out.balls_.clear();
    for (const Box& box : boxes_)
      if (box_distance(centre, box) < radius) out.boxes_.push_back(box);
    for (const Ball& ball : balls_)
      if ((centre - ball.centre).norm() - ball.radius < radius) out.balls_.push_back(ball);
    return out;
  }

  const Box& inside() const { return inside_; }

 private:
  Box inside_;
  std::vector<Box> boxes_;
  std::vector<Ball> balls_;
};

}  // namespace

storage::MemoryChunkStore make_hall_map(const Eigen::Vector3d& size_m, double voxel_size_m,
                                        double truncation_m) {
  storage::MapMetadata metadata;
  metadata.voxel_size_m = voxel_size_m;
  metadata.truncation_m = truncation_m;
  metadata.max_weight = 100.0;
  metadata.sensor = "synthetic hall";
  storage::MemoryChunkStore store(metadata);
  const Hall hall(size_m);

  // Every chunk that reaches the hall or its walls (to tau behind them).
  auto voxel = [&](double metres) {
    return static_cast<int64_t>(std::floor(metres / voxel_size_m));
  };
  const Eigen::Vector3d lo = hall.inside().lo.array() - truncation_m;
  const Eigen::Vector3d hi = hall.inside().hi.array() + truncation_m;
  const storage::ChunkKey first =
      storage::chunk_of_voxel(voxel(lo.x()), voxel(lo.y()), voxel(lo.z()));
  const storage::ChunkKey last =
      storage::chunk_of_voxel(voxel(hi.x()), voxel(hi.y()), voxel(hi.z()));
  std::vector<storage::ChunkKey> keys;
  for (int32_t x = first.x; x <= last.x; ++x)
    for (int32_t y = first.y; y <= last.y; ++y)
      for (int32_t z = first.z; z <= last.z; ++z) keys.push_back({x, y, z});

  std::vector<storage::Chunk> chunks(keys.size());
  const auto tau = static_cast<float>(truncation_m);
  tbb::parallel_for(size_t{0}, keys.size(), [&](size_t i) {
    const storage::ChunkKey& key = keys[i];
    storage::Chunk& chunk = chunks[i];
    const double chunk_m = storage::kChunkSize * voxel_size_m;
    const Eigen::Vector3d centre = (Eigen::Vector3d(key.x, key.y, key.z).array() + 0.5) * chunk_m;
    const Hall local = hall.near(centre, 0.5 * std::sqrt(3.0) * chunk_m + truncation_m);
    // Blocks of 8^3 voxels see only the objects near them: a few instead of a hundred.
    constexpr int32_t kBlock = 8;
    const double block_m = kBlock * voxel_size_m;
    for (int32_t bz = 0; bz < storage::kChunkSize; bz += kBlock)
      for (int32_t by = 0; by < storage::kChunkSize; by += kBlock)
        for (int32_t bx = 0; bx < storage::kChunkSize; bx += kBlock) {
          const Eigen::Vector3d block_centre =
              Eigen::Vector3d(key.x * storage::kChunkSize + bx, key.y * storage::kChunkSize + by,
                              key.z * storage::kChunkSize + bz) *
                  voxel_size_m +
              Eigen::Vector3d::Constant(0.5 * block_m);
          const Hall block =
              local.near(block_centre, 0.5 * std::sqrt(3.0) * block_m + truncation_m);
          for (int32_t z = bz; z < bz + kBlock; ++z)
            for (int32_t y = by; y < by + kBlock; ++y)
              for (int32_t x = bx; x < bx + kBlock; ++x) {
                const Eigen::Vector3d p = (Eigen::Vector3d(key.x * storage::kChunkSize + x,
                                                           key.y * storage::kChunkSize + y,
                                                           key.z * storage::kChunkSize + z)
                                               .array() +
                                           0.5) *
                                          voxel_size_m;
                const double d = block.distance(p);
                if (d < -truncation_m) continue;  // never seen: behind a surface
                tsdf::Voxel v;
                v.value = static_cast<int16_t>(tsdf::distance_to_fixed(static_cast<float>(d), tau));
                v.weight = static_cast<uint16_t>(4 * tsdf::kWeightScale);
                chunk.at(x, y, z) = tsdf::pack(v);
              }
        }
  });
  for (size_t i = 0; i < keys.size(); ++i) store.write(keys[i], chunks[i]);
  return store;
}

}  // namespace featsense::bench
