// Voting and blur (paper 3.3): the cache space counts points, the blur keeps a lone vote's height.
#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/hough_voting.h"

using namespace hough_plane_detector;

namespace
{
WindowSample windowOn(const Eigen::Vector3d& normal, double d, int count)
{
  WindowSample sample;
  sample.normal = normal.normalized();
  sample.d = d;
  sample.centroid = -d * sample.normal;
  sample.count = count;
  sample.window_x = sample.window_y = 0;
  return sample;
}

struct Grid
{
  DetectorParams params;
  HoughParameterization param{params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance, 8};
  SparseHoughSpace space{param.sizeAngle(), param.sizeAngle(), param.sizeD()};
};
}  // namespace

TEST(HoughVoting, WindowsOfOnePlaneSumTheirPointsInOneCell)
{
  Grid grid;
  HoughVoting voting(grid.param, 2, 1.0);
  const Eigen::Vector3d n(0.3, -0.2, 0.93);
  const std::vector<WindowSample> samples{windowOn(n, -2.0, 64), windowOn(n, -2.0, 40), windowOn(-n, 1.0, 10)};
  EXPECT_EQ(voting.vote(samples, 0.25f, grid.space), 0);
  ASSERT_EQ(voting.cache().size(), 2u);  // two planes, neither near the chart border
  float total = 0.0f, largest = 0.0f;
  for (const auto& entry : voting.cache())
  {
    total += entry.second;
    largest = std::max(largest, entry.second);
  }
  EXPECT_FLOAT_EQ(total, 0.25f * (64 + 40 + 10));
  EXPECT_FLOAT_EQ(largest, 0.25f * (64 + 40));
}

TEST(HoughVoting, PlanesBeyondMaxDistanceAreCountedNotVoted)
{
  Grid grid;
  HoughVoting voting(grid.param, 2, 1.0);
  const std::vector<WindowSample> samples{windowOn(Eigen::Vector3d(0.2, 0.1, 1.0), -(grid.params.max_distance + 1.0), 64)};
  EXPECT_EQ(voting.vote(samples, 1.0f, grid.space), 1);
  EXPECT_TRUE(voting.cache().empty());
}

TEST(HoughVoting, BlurKeepsALoneVotesHeightAndSpreadsItByTheKernel)
{
  Grid grid;
  HoughVoting voting(grid.param, 2, 1.0);
  voting.vote({windowOn(Eigen::Vector3d(0.1, 0.4, 0.9), -1.5, 100)}, 1.0f, grid.space);
  ASSERT_EQ(voting.cache().size(), 1u);
  const Eigen::Vector3i c = voting.cache()[0].first;
  voting.blur(grid.space);
  EXPECT_FLOAT_EQ(grid.space.value(c.x(), c.y(), c.z()), 100.0f);
  EXPECT_NEAR(grid.space.value(c.x() + 1, c.y(), c.z()), 100.0f * std::exp(-0.5), 1e-3);
  EXPECT_NEAR(grid.space.value(c.x() + 1, c.y() - 1, c.z() + 1), 100.0f * std::exp(-1.5), 1e-3);
  EXPECT_EQ(grid.space.value(c.x() + 3, c.y(), c.z()), 0.0f);  // beyond the kernel's radius
}

TEST(HoughVoting, AGaussianSitsOnItsSubVoxelCentre)
{
  Grid grid;
  HoughVoting voting(grid.param, 2, 1.0);
  const Eigen::Vector3d cell(200.3, 180.7, 900.45);
  voting.addGaussian(grid.space, grid.param.fromCell(cell), 1.0f, 20.0f);
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (int x = 198; x <= 203; ++x)
    for (int y = 178; y <= 183; ++y)
      for (int z = 898; z <= 903; ++z)
      {
        const double v = grid.space.value(x, y, z);
        weighted += v * Eigen::Vector3d(x, y, z);
        total += v;
      }
  // Within the truncated kernel the mean leans a little to the centre cell; rounding would be 0.62 off.
  EXPECT_LT((weighted / total - cell).norm(), 0.1);
  // The cap bounds every cell.
  voting.addGaussian(grid.space, grid.param.fromCell(cell), 50.0f, 20.0f);
  EXPECT_LE(grid.space.value(200, 181, 900), 20.0f);
}
