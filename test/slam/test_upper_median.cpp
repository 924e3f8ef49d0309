#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "featsense/slam/upper_median.hpp"

namespace featsense::slam {
namespace {

TEST(UpperMedian, AnOddCountGivesTheMiddleValueInOrder) {
  std::vector<double> values = {5.0, -1.0, 9.0, 3.0, 7.0};
  EXPECT_EQ(upper_median(values), 5.0);
}

TEST(UpperMedian, AnEvenCountGivesTheUpperOfTheTwoMiddleValuesNotTheirMean) {
  std::vector<double> values = {4.0, 1.0, 3.0, 2.0};
  EXPECT_EQ(upper_median(values), 3.0);
  std::vector<int64_t> periods = {10'000'000, 9'000'000};
  EXPECT_EQ(upper_median(periods), 10'000'000);
}

TEST(UpperMedian, OneValueIsItsOwnMedianAndOutliersDoNotMoveIt) {
  std::vector<float> one = {2.5f};
  EXPECT_EQ(upper_median(one), 2.5f);
  std::vector<double> with_jolts = {1.0, 1.1, 0.9, 1.0, 1e9, -1e9, 1.05};
  EXPECT_EQ(upper_median(with_jolts), 1.0);
}

}  // namespace
}  // namespace featsense::slam
