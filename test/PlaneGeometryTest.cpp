#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "hough_plane_detector/core/plane_geometry.h"

using namespace hough_plane_detector;

namespace
{
// The definition: sorted, the first value at which the running weight reaches half.
double sortedWeightedMedian(std::vector<std::pair<double, double>> values, double total)
{
  std::sort(values.begin(), values.end());
  double below = 0.0;
  for (const auto& value : values)
    if ((below += value.second) >= 0.5 * total) return value.first;
  return values.back().first;
}
}  // namespace

TEST(PlaneGeometry, WeightedMedianIsTheSortedDefinition)
{
  // Block offsets weighted by their point counts (integers, as the snap gives them), with ties.
  std::mt19937 random(5);
  std::uniform_int_distribution<int> count(1, 200), points(1, 64), tie(0, 3);
  std::normal_distribution<double> offset(1.0, 0.01);
  for (int trial = 0; trial < 2000; ++trial)
  {
    std::vector<std::pair<double, double>> values;
    double total = 0.0;
    const int n = count(random);
    for (int i = 0; i < n; ++i)
    {
      const double d = tie(random) == 0 && !values.empty() ? values.back().first : offset(random);
      values.emplace_back(d, points(random));
      total += values.back().second;
    }
    const double expected = sortedWeightedMedian(values, total);
    ASSERT_EQ(weightedMedian(values, total), expected) << trial;
  }
}

TEST(PlaneGeometry, WeightedMedianIgnoresALeaningMinority)
{
  // Most points on d = 2.00 (five blocks); two blocks leaning off it on one side, heavier than
  // any one of them, must not pull it (a mean would move to 2.026).
  std::vector<std::pair<double, double>> values = {{2.0, 64}, {2.0, 64}, {2.001, 64}, {1.999, 64}, {2.0, 64},
                                                   {2.08, 100}, {2.09, 100}};
  EXPECT_NEAR(weightedMedian(values, 520.0), 2.0, 0.0015);  // 2.001: the running weight reaches 260 there
  std::vector<std::pair<double, double>> none;
  EXPECT_TRUE(std::isnan(weightedMedian(none, 0.0)));
}
