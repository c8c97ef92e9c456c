// The planarity tests of a per-frame plane on rendered frames.
#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/core/planarity_tests.h"
#include "frame_fixture.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

TEST(PlanarityTests, AWallPassesAndAPillarFails)
{
  Frame f;
  const std::vector<int> wall = f.blocksOn(f.truePlane("wall"));
  const std::vector<int> pillar = f.blocksOn(-1);
  ASSERT_GT(wall.size(), 100u);
  ASSERT_GT(pillar.size(), 30u);
  EXPECT_TRUE(f.tests.isPlanarFit(f.tests.weightedMoments(wall), wall));
  EXPECT_TRUE(f.tests.halvesAgree(wall, 0, wall.size(), f.params.merge_angle));
  EXPECT_FALSE(f.tests.isPlanarFit(f.tests.weightedMoments(pillar), pillar));
}

// Along the floor's normal a floor block is as thin as its depth noise makes it; a block
// across the step's top edge holds points of an upright face below the top's and is thicker.
TEST(PlanarityTests, ABlockAcrossAnEdgeIsThickerThanItsNoise)
{
  Frame f;
  const Eigen::Vector3d up = f.frame.normalInCamera(Eigen::Vector3d::UnitZ());
  const int top = f.truePlane("step_top");
  ASSERT_GE(top, 0);
  const int s = blockSize(f.params.normal_window, f.params.normal_stride);
  int floor_thin = 0, edge_thin = 0, edge = 0;
  const std::vector<int> floor = f.blocksOn(f.truePlane("floor"));
  for (int b : floor) floor_thin += f.tests.isThinAlong(b, up);
  for (size_t b = 0; b < f.frame.blocks.size(); ++b)
  {
    if (!f.frame.blocks[b].valid) continue;
    const int bx = static_cast<int>(b) % f.frame.blocksX(), by = static_cast<int>(b) / f.frame.blocksX();
    int on_top = 0, on_upright = 0;
    for (int v = by * s; v < (by + 1) * s; ++v)
      for (int u = bx * s; u < (bx + 1) * s; ++u)
      {
        const int plane = f.rendered.pixel_plane[static_cast<size_t>(v) * f.rendered.width + u];
        on_top += plane == top;
        on_upright += plane >= 0 && plane != top && std::abs(f.renderer.truePlanes()[plane].normal.z()) < 0.1;
      }
    if (on_top < s * s / 4 || on_upright < s * s / 4) continue;
    ++edge;
    edge_thin += f.tests.isThinAlong(static_cast<int>(b), up);
  }
  ASSERT_GT(floor.size(), 500u);
  ASSERT_GE(edge, 5);
  EXPECT_GE(floor_thin, 0.97 * floor.size());
  EXPECT_EQ(edge_thin, 0);
}

TEST(PlanarityTests, AFaceBowedLikeCardboardPassesACanFails)
{
  // Real box faces bow by about 1/m (osd-learn); a can's side turns 30 times as fast. Both
  // patches are 15 cm wide, 1 m ahead: their halves tilt apart by more than merge_angle and
  // far beyond the noise, but only the can bends faster than a plane may (kMaxPlaneCurvature).
  for (const double radius : {1.0, 0.25})
  {
    Scene scene;
    scene.cylinders.push_back({Eigen::Vector3d(1.0 + radius, 0, 0), radius, 2.0});
    Frame f(scene, lookAt(Eigen::Vector3d(0, 0, 1.0), Eigen::Vector3d(1, 0, 1.0)));
    std::vector<int> patch;
    for (int b : f.blocksOn(-1))
      if (std::abs(f.frame.blocks[b].centroid.x()) < 0.075 && std::abs(f.frame.blocks[b].centroid.y()) < 0.2)
        patch.push_back(b);
    ASSERT_GT(patch.size(), 60u) << "radius " << radius;
    EXPECT_EQ(f.tests.halvesAgree(patch, 0, patch.size(), f.params.merge_angle), radius > 1.0 / kMaxPlaneCurvature)
        << "radius " << radius;
  }
}

TEST(PlanarityTests, TheLikelihoodRatioTellsTheTrueNormalFromOneDegreeOff)
{
  Frame f;
  const std::vector<int> wall = f.blocksOn(f.truePlane("wall"));
  const Eigen::Vector3d n_cam = f.frame.normalInCamera(f.renderer.truePlanes()[f.truePlane("wall")].normal);
  EXPECT_TRUE(f.tests.explainNormal(n_cam, wall, false).interior);
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitX()) * n_cam;
  EXPECT_GT(f.tests.snapChi2Increase(tilted, wall), kMaxSnapChi2Increase);
  EXPECT_FALSE(f.tests.explainNormal(tilted, wall, false).interior);
}

TEST(PlanarityTests, ANormalNeedsSpreadAcrossMoreThanAFewBlocks)
{
  Frame f;
  const std::vector<int> wall = f.blocksOn(f.truePlane("wall"));
  ASSERT_GT(wall.size(), 100u);
  const double bound = f.params.merge_angle / 2.0;  // FramePlaneFitter's limit
  EXPECT_LT(f.tests.normalUncertainty(wall), 0.2 * bound);
  // One image row of the wall's blocks: a line in space, no tilt about it is measured.
  const int row = f.wallRow(wall);
  std::vector<int> strip;
  for (int b : wall)
    if (b / f.frame.blocksX() == row) strip.push_back(b);
  ASSERT_GT(strip.size(), 20u);
  EXPECT_GT(f.tests.normalUncertainty(strip), bound);
  // Nor may a few blocks off the row (a strip along a shelf's edge and some on the wall).
  int added = 0;
  for (int b : wall)
    if (b / f.frame.blocksX() == row + 10 && added < 3) strip.push_back(b), ++added;
  ASSERT_EQ(added, 3);
  EXPECT_GT(f.tests.normalUncertainty(strip), bound);
  // Three rows do.
  for (int b : wall)
    if (b / f.frame.blocksX() == row + 1 || b / f.frame.blocksX() == row + 2) strip.push_back(b);
  EXPECT_LT(f.tests.normalUncertainty(strip), bound);
}

TEST(PlanarityTests, AnUnorientedStripOfAWallFitsUprightALevelPatchDoesNot)
{
  Frame f;
  const std::vector<int> wall = f.blocksOn(f.truePlane("wall"));
  const double bound = f.params.merge_angle / 2.0;  // FramePlaneFitter's limit
  const Eigen::Vector3d up = f.frame.normalInCamera(Eigen::Vector3d::UnitZ());
  // One image row of the wall: its own points fix no tilt about the row (see above), but
  // among upright planes only the wall's contains it.
  const int row = f.wallRow(wall);
  std::vector<int> strip;
  for (int b : wall)
    if (b / f.frame.blocksX() == row) strip.push_back(b);
  ASSERT_GT(f.tests.normalUncertainty(strip), bound);
  Eigen::Vector3d n_cam;
  double d_cam = 0.0, sigma = 0.0;
  ASSERT_TRUE(f.tests.uprightNormal(strip, up, n_cam, d_cam, sigma));
  const TruePlane& truth = f.renderer.truePlanes()[f.truePlane("wall")];
  EXPECT_LT(angleBetween(f.frame.normalInWorld(n_cam), truth.normal), 0.01);
  EXPECT_NEAR(std::abs(n_cam.dot(up)), 0.0, 1e-12);
  EXPECT_LT(sigma, bound);
  // A patch of the floor, three block rows deep, lies on no upright plane.
  const std::vector<int> floor = f.blocksOn(f.truePlane("floor"));
  const int floor_row = f.wallRow(floor);
  std::vector<int> patch;
  for (int b : floor)
    if (std::abs(b / f.frame.blocksX() - floor_row) <= 1) patch.push_back(b);
  ASSERT_GT(patch.size(), 30u);
  EXPECT_FALSE(f.tests.uprightNormal(patch, up, n_cam, d_cam, sigma));
}
