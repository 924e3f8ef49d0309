// The free-space walks eight at a time (free_space_lanes.hpp) against the plain statement of
// the walk, march_ray (ray_marcher.hpp): the free space a walk proposes, set for set, on a map
// whose ring buffer wraps inside it, from sensors inside and outside the map, with ties at
// every crossing, more words than one call writes out, and settled bricks.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "analytic_rays.hpp"
#include "cpu_fast/free_space_lanes.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"
#include "ray_marcher.hpp"
#include "ray_walk.hpp"
#include "varied_rays.hpp"

namespace featsense::tsdf {
namespace {

using Ray = std::pair<Vec3, Vec3>;  // origin, end point

/// The free space proposed to a visitor, voxel by voxel, less the bricks `settled` names.
struct FreeSet {
  const uint8_t* settled = nullptr;
  std::set<size_t> voxels;
  void add(size_t index) {
    if (settled == nullptr || settled[index / kBrickVoxels] == 0) voxels.insert(index);
  }
  void add_word(size_t word, uint64_t bits) {
    for (; bits != 0; bits &= bits - 1) add(word * 64 + static_cast<size_t>(__builtin_ctzll(bits)));
  }
};

/// march_ray's free space: every +tau candidate that is not interpolated.
struct MarchVisitor {
  FreeSet* free;
  void operator()(size_t index, int32_t value, bool interpolated) {
    if (value == kValueScale && !interpolated) free->add(index);
  }
};

/// The walk's, the free space at the end of each walk set aside.
struct WalkVisitor {
  static constexpr bool kTakesFreeWalks = true;
  FreeSet* free;
  std::vector<detail::FreeWalk>* walks;
  void operator()(size_t index, int32_t value, bool interpolated) {
    if (value == kValueScale && !interpolated) free->add(index);
  }
  void free_walk(const detail::FreeWalk& walk) { walks->push_back(walk); }
};

class FreeSpaceLanesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!detail::FreeSpaceLanes::supported()) GTEST_SKIP() << "this processor has no AVX2";
  }
};

TEST_F(FreeSpaceLanesTest, LanesWalkTheFreeSpaceMarchRayProposes) {
  TsdfSettings s;
  // Centred off the origin, so that the ring buffer's seam (slot 0) lies inside the map on
  // every axis and many walks cross it.
  const LocalMapGeometry map = centred_geometry(s, test::make_vec(-7.3, 11.9, 3.4));
  const Index3 lowest = map.wrapped_brick(map.origin);
  ASSERT_NE(lowest.x, 0);
  ASSERT_NE(lowest.y, 0);
  ASSERT_NE(lowest.z, 0);
  std::vector<uint8_t> settled(map.voxel_count() / kBrickVoxels);
  std::mt19937 random(31);
  for (uint8_t& brick : settled) brick = random() % 3 == 0 ? 1 : 0;

  const std::vector<Ray> rays = test::varied_rays(s.voxel_size_m, 9.5f, 1500, random);
  const uint8_t* const brick_sets[] = {nullptr, settled.data()};
  for (const uint8_t* bricks : brick_sets) {
    FreeSet reference{bricks, {}};
    FreeSet lanes_free{bricks, {}};
    FreeSet scalar_free{bricks, {}};
    std::vector<detail::FreeWalk> walks;
    for (size_t k = 0; k < rays.size(); ++k) {
      detail::RayMarchParams params;
      params.truncation_m = s.truncation_m;
      params.interpolation_slope = k % 2 == 0 ? 0.006f : 0.0f;
      params.carve_from_m = k % 3 == 1 ? 2.5f : 0.0f;
      const auto& [origin, endpoint] = rays[k];
      detail::march_ray(origin, endpoint, map, params, MarchVisitor{&reference});
      const size_t before = walks.size();
      detail::walk_ray(origin, endpoint, map, params, WalkVisitor{&lanes_free, &walks}, bricks);
      // The same walks' band part once more, for the scalar loop.
      std::vector<detail::FreeWalk> again;
      detail::walk_ray(origin, endpoint, map, params, WalkVisitor{&scalar_free, &again}, bricks);
      ASSERT_EQ(again.size(), walks.size() - before);
    }
    ASSERT_GT(walks.size(), rays.size() / 2);  // most rays end in free space

    // The scalar loop, settled bricks jumped across.
    const detail::FreeSpaceMap free_map = detail::FreeSpaceMap::of(map);
    struct Words {
      FreeSet* free;
      void free_word(size_t word, uint64_t bits) { free->add_word(word, bits); }
    } scalar_words{&scalar_free};
    for (const detail::FreeWalk& walk : walks)
      detail::walk_free_space_job(walk, free_map, bricks, scalar_words);

    // The lanes, in two batches (the second after the first is done), output taken as often
    // as it fills.
    detail::FreeSpaceLanes lanes;
    size_t calls = 0;
    const size_t half = walks.size() / 2;
    for (const auto& [first, count] : {std::pair{size_t{0}, half}, {half, walks.size() - half}}) {
      lanes.start(walks.data() + first, count, free_map);
      bool more = true;
      while (more) {
        more = lanes.walk();
        ++calls;
        for (size_t k = 0; k < lanes.words(); ++k) {
          lanes_free.add_word(static_cast<size_t>(lanes.word(k)), lanes.bits(k));
        }
      }
    }
    EXPECT_GT(calls, 4u);  // more words than one call writes out
    EXPECT_GT(reference.voxels.size(), 100000u);
    EXPECT_TRUE(scalar_free.voxels == reference.voxels) << (bricks ? "settled" : "none settled");
    EXPECT_TRUE(lanes_free.voxels == reference.voxels) << (bricks ? "settled" : "none settled");
  }
}

TEST_F(FreeSpaceLanesTest, NoWalksNoWords) {
  detail::FreeSpaceLanes lanes;
  lanes.start(nullptr, 0, detail::FreeSpaceMap{{3, 3, 3}, {0, 0, 0}});
  EXPECT_FALSE(lanes.walk());
  EXPECT_EQ(lanes.words(), 0u);
}

}  // namespace
}  // namespace featsense::tsdf
