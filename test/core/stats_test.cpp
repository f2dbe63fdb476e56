#include "ret3d/core/stats.h"

#include <gtest/gtest.h>

namespace ret3d {
namespace {

TEST(Stats, EmptySampleGivesZero) {
  EXPECT_EQ(percentile({}, 50), 0.0);
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(nearestRankPercentile({}, 95), 0.0);
}

TEST(Stats, PercentileInterpolatesBetweenSortedValues) {
  const std::vector<double> v{40, 10, 30, 20};  // unsorted on purpose
  EXPECT_DOUBLE_EQ(percentile(v, 0), 10);
  EXPECT_DOUBLE_EQ(percentile(v, 100), 40);
  EXPECT_DOUBLE_EQ(percentile(v, 50), 25);
  EXPECT_DOUBLE_EQ(percentile(v, 90), 37);  // position 0.9 * 3 = 2.7 between 30 and 40
  EXPECT_DOUBLE_EQ(percentile(v, 150), 40);  // clamped
  EXPECT_DOUBLE_EQ(percentile(v, -5), 10);
}

TEST(Stats, MedianOfOddAndEvenCounts) {
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2);
  EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_DOUBLE_EQ(median({7}), 7);
}

TEST(Stats, NearestRankIsAlwaysOneOfTheValues) {
  std::vector<double> v;
  for (int i = 20; i >= 1; --i) v.push_back(i);  // 1 .. 20
  EXPECT_DOUBLE_EQ(nearestRankPercentile(v, 95), 19);  // ceil(0.95 * 20) = 19th smallest
  EXPECT_DOUBLE_EQ(nearestRankPercentile(v, 100), 20);
  EXPECT_DOUBLE_EQ(nearestRankPercentile(v, 50), 10);
  EXPECT_DOUBLE_EQ(nearestRankPercentile({5, 1}, 95), 5);
  EXPECT_DOUBLE_EQ(nearestRankPercentile({5, 1}, 0), 1);
}

}  // namespace
}  // namespace ret3d
