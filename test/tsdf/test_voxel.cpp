#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf {
namespace {

TEST(Voxel, PackUnpackRoundTripsEveryValueAndWeight) {
  for (int32_t value : {-32767, -1, 0, 1, 12345, 32767}) {
    for (uint32_t weight : {0u, 1u, 64u, 640u, 65535u}) {
      const Voxel v{static_cast<int16_t>(value), static_cast<uint16_t>(weight)};
      const Voxel back = unpack(pack(v));
      EXPECT_EQ(back.value, v.value);
      EXPECT_EQ(back.weight, v.weight);
    }
  }
  EXPECT_EQ(sizeof(Voxel), 4u);
  EXPECT_EQ(pack(Voxel{}), kUnobservedVoxel);
}

TEST(Voxel, DistancesClampToTruncationAndRoundToTheNearestUnit) {
  const float tau = 0.6f;
  EXPECT_EQ(distance_to_fixed(0.0f, tau), 0);
  EXPECT_EQ(distance_to_fixed(0.6f, tau), kValueScale);
  EXPECT_EQ(distance_to_fixed(5.0f, tau), kValueScale);
  EXPECT_EQ(distance_to_fixed(-5.0f, tau), -kValueScale);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> distance(-0.6f, 0.6f);
  for (int i = 0; i < 1000; ++i) {
    const float d = distance(rng);
    const int32_t fixed = distance_to_fixed(d, tau);
    // Within half a unit (tau / 32767 / 2), plus float rounding.
    EXPECT_NEAR(fixed_to_distance(fixed, tau), d, 0.5 * tau / kValueScale + 1e-6);
  }
}

TEST(Voxel, CandidateOrderIsMeasuredFirstThenSmallestMagnitude) {
  const uint32_t measured_far = make_candidate(30000, false);
  const uint32_t interpolated_zero = make_candidate(0, true);
  EXPECT_LT(measured_far, interpolated_zero);  // a real measurement always wins
  EXPECT_LT(make_candidate(-5, false), make_candidate(6, false));
  EXPECT_LT(make_candidate(5, false), make_candidate(-5, false));  // ties: positive wins
  EXPECT_LT(make_candidate(-kValueScale, true), kEmptyCandidate);
  for (int32_t value : {-kValueScale, -3, 0, 3, kValueScale}) {
    for (bool interpolated : {false, true}) {
      const uint32_t key = make_candidate(value, interpolated);
      EXPECT_EQ(candidate_value(key), value);
      EXPECT_EQ(candidate_interpolated(key), interpolated);
    }
  }
}

TEST(Voxel, WeightIsFullInFrontAndFallsOffBehindTheSurface) {
  const int32_t falloff = distance_to_fixed(0.064f, 0.6f);
  EXPECT_EQ(candidate_weight(kValueScale, falloff), static_cast<uint32_t>(kWeightScale));
  EXPECT_EQ(candidate_weight(0, falloff), static_cast<uint32_t>(kWeightScale));
  EXPECT_EQ(candidate_weight(-falloff, falloff), static_cast<uint32_t>(kWeightScale));
  EXPECT_EQ(candidate_weight(-kValueScale, falloff), 0u);
  const uint32_t half_way = candidate_weight(-(kValueScale + falloff) / 2, falloff);
  EXPECT_NEAR(static_cast<double>(half_way), kWeightScale / 2.0, 1.0);
  uint32_t previous = kWeightScale;
  for (int32_t v = -falloff; v >= -kValueScale; v -= 97) {
    const uint32_t w = candidate_weight(v, falloff);
    EXPECT_LE(w, previous);
    previous = w;
  }
}

TEST(Voxel, FuseIsTheWeightedAverageOfThePaperCappedAtMaxWeight) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int32_t> value(-kValueScale, kValueScale);
  std::uniform_int_distribution<uint32_t> weight(0, 640);
  const uint32_t max_weight = 640;
  for (int i = 0; i < 10000; ++i) {
    const Voxel g{static_cast<int16_t>(value(rng)), static_cast<uint16_t>(weight(rng))};
    const int32_t v = value(rng);
    const uint32_t w = weight(rng);
    const Voxel out = fuse(g, v, w, max_weight);
    if (w == 0) {
      EXPECT_EQ(pack(out), pack(g));
      continue;
    }
    const double expected =
        (static_cast<double>(g.value) * g.weight + static_cast<double>(v) * w) / (g.weight + w);
    EXPECT_LE(std::abs(out.value - expected), 0.5 + 1e-9);
    EXPECT_EQ(out.weight, std::min<uint32_t>(max_weight, g.weight + w));
  }
}

TEST(Voxel, FusingTheSameValueKeepsIt) {
  Voxel g{};
  for (int i = 0; i < 50; ++i) g = fuse(g, -1234, kWeightScale, 640);
  EXPECT_EQ(g.value, -1234);
  EXPECT_EQ(g.weight, 640);
}

}  // namespace
}  // namespace featsense::tsdf
