// The measurement model's parts against the lidar equation and the Ouster noise figures.

#include <gtest/gtest.h>

#include <cmath>

#include "featsense/slam/sim/measurement_model.hpp"

namespace featsense::slam {
namespace {

HitGeometry hit(double range_m, double cos_incidence, double reflectance) {
  HitGeometry g;
  g.range_m = range_m;
  g.cos_incidence = cos_incidence;
  g.reflectance = reflectance;
  g.max_range_m = 120.0;
  return g;
}

TEST(SimMeasurementModel, IntensityFollowsTheLidarEquation) {
  const float near = intensity_of(hit(5.0, 1.0, 0.5));
  EXPECT_NEAR(intensity_of(hit(10.0, 1.0, 0.5)), near / 4.0f, near * 1e-5f);  // 1 / r^2
  EXPECT_NEAR(intensity_of(hit(5.0, 0.5, 0.5)), near / 2.0f, near * 1e-5f);   // cos
  EXPECT_NEAR(intensity_of(hit(5.0, 1.0, 0.25)), near / 2.0f, near * 1e-5f);  // reflectance
}

TEST(SimMeasurementModel, NoiseGrowsWithRangeAndWeakReturnsWithinOustersBounds) {
  const MeasurementSettings s;
  const double near_bright = range_sigma_m(hit(1.0, 1.0, 0.8), s);
  const double far_bright = range_sigma_m(hit(60.0, 1.0, 0.8), s);
  const double near_dark = range_sigma_m(hit(30.0, 0.3, 0.06), s);
  EXPECT_LT(near_bright, far_bright);
  EXPECT_LT(range_sigma_m(hit(30.0, 1.0, 0.8), s), near_dark);
  // Errors are truncated at 3 sigma: +-1.5 cm at best, +-10 cm at worst (Ouster's figures).
  for (double r : {0.5, 2.0, 10.0, 50.0, 119.0}) {
    for (double rho : {0.02, 0.1, 0.5, 0.95}) {
      const double sigma = range_sigma_m(hit(r, 0.7, rho), s);
      EXPECT_GE(3.0 * sigma, 0.015 - 1e-12);
      EXPECT_LE(3.0 * sigma, 0.10 + 1e-12);
    }
  }
}

TEST(SimMeasurementModel, DropOutsAtGrazingOnDarkSurfacesAndBeyondReach) {
  const MeasurementSettings s;
  // Grazing: beyond the limit never, just inside it (near, bright) always returns.
  EXPECT_TRUE(drops_out(hit(3.0, std::cos(s.grazing_limit_rad + 0.01), 0.8), s, 0.0));
  EXPECT_FALSE(drops_out(hit(3.0, std::cos(s.grazing_limit_rad - 0.05), 0.8), s, 0.99));
  // Dark: a 2.5 % surface (half the threshold) returns for half of the draws.
  int kept = 0;
  for (int k = 0; k < 1000; ++k) kept += drops_out(hit(3.0, 1.0, 0.025), s, k / 1000.0) ? 0 : 1;
  EXPECT_EQ(kept, 500);
  // Reach: a head-on target of the reference reflectance returns up to max range; one of a
  // quarter of it up to half of max range (power ~ reflectance / r^2).
  EXPECT_FALSE(drops_out(hit(119.0, 1.0, 0.8), s, 0.5));
  EXPECT_FALSE(drops_out(hit(59.0, 1.0, 0.2), s, 0.5));
  EXPECT_TRUE(drops_out(hit(61.0, 1.0, 0.2), s, 0.5));
}

}  // namespace
}  // namespace featsense::slam
