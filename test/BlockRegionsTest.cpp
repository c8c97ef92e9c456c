// Block statistics and region growing on a rendered frame: a floor, a wall 3.5 m ahead, a step
// before it and a pillar.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "hough_plane_detector/core/block_regions.h"
#include "frame_fixture.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

namespace
{
// Share of `blocks` whose pixels lie on true plane `index`.
double shareOn(const Frame& f, const std::vector<int>& blocks, int index)
{
  const std::vector<int> on = f.blocksOn(index);
  int inside = 0;
  for (int b : blocks) inside += std::find(on.begin(), on.end(), b) != on.end();
  return blocks.empty() ? 0.0 : static_cast<double>(inside) / blocks.size();
}
}  // namespace

TEST(BlockRegions, BlocksOfTheWallAreFlatAndFaceTheirPlane)
{
  Frame f;
  const TruePlane& wall = f.renderer.truePlanes()[f.truePlane("wall")];
  const Eigen::Vector3d n_cam = f.frame.normalInCamera(wall.normal);
  const std::vector<int> blocks = f.blocksOn(f.truePlane("wall"));
  ASSERT_GT(blocks.size(), 100u);
  int planar = 0, within_tolerance = 0;
  for (int b : blocks)
  {
    const BlockInfo& info = f.frame.blocks[b];
    planar += info.planar;
    const double angle = std::acos(std::min(1.0, std::abs(info.normal.dot(n_cam))));
    within_tolerance += angle <= info.normal_tolerance;
    // The centroid lies on the true plane within the residual a region allows it.
    EXPECT_LE(std::abs(n_cam.dot(info.centroid) + f.frame.dInCamera(wall.normal, wall.d)), info.region_residual) << b;
  }
  EXPECT_GE(planar, 0.95 * blocks.size());
  EXPECT_GE(within_tolerance, 0.95 * blocks.size());
}

TEST(BlockRegions, TheWallGrowsOverItselfAndNotOntoTheFloor)
{
  Frame f;
  const TruePlane& wall = f.renderer.truePlanes()[f.truePlane("wall")];
  const Eigen::Vector3d n_cam = f.frame.normalInCamera(wall.normal);
  const double d_cam = f.frame.dInCamera(wall.normal, wall.d);
  BlockRegionGrower grower(f.frame.normals, f.frame.blocks, f.params);
  const std::vector<char> taken(f.frame.blocks.size(), 0);
  const auto seeds = grower.seedComponents(n_cam, d_cam, taken);
  ASSERT_FALSE(seeds.empty());
  const PlaneRegion region = grower.grow(seeds.front(), n_cam, d_cam, taken);
  // Nearly every block of the region is on the wall (rim blocks may straddle its edges), and it
  // covers most of the wall's whole blocks.
  EXPECT_GE(shareOn(f, region.blocks, f.truePlane("wall")), 0.9);
  EXPECT_GE(region.blocks.size(), 0.8 * f.blocksOn(f.truePlane("wall")).size());
  EXPECT_LT(std::acos(std::min(1.0, std::abs(region.normal.dot(n_cam)))), 0.01);
  EXPECT_NEAR(region.d, d_cam, 0.02);
  EXPECT_EQ(shareOn(f, region.blocks, f.truePlane("floor")), 0.0);
}

TEST(BlockRegions, ThePillarsCentroidsBendAndTheWallsDoNot)
{
  Frame f;
  BlockRegionGrower grower(f.frame.normals, f.frame.blocks, f.params);
  const std::vector<int> pillar = f.blocksOn(-1), wall = f.blocksOn(f.truePlane("wall"));
  ASSERT_GT(pillar.size(), 30u);
  Eigen::Vector3d normal;
  double d;
  ASSERT_TRUE(grower.fit(pillar, normal, d));
  EXPECT_TRUE(grower.centroidsBend(pillar, normal, d));
  ASSERT_TRUE(grower.fit(wall, normal, d));
  EXPECT_FALSE(grower.centroidsBend(wall, normal, d));
  EXPECT_FALSE(grower.normalsTurn(wall, normal));
}

namespace
{
// Blocks of `spacing` (1 cm) on z = depth + curvature x^2 / 2 (camera frame) covering width x
// height metres, each centroid known to model_sigma (0.2 mm) and each normal to 0.01 rad: the
// bend is far beyond noise. With scatter > 0 the centroids are moved by that much Gaussian noise.
std::vector<BlockInfo> bentPatch(double curvature, double width, double height, double depth, double spacing = 0.01,
                                 double model_sigma = 0.0002, double scatter = 0.0)
{
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<BlockInfo> blocks;
  for (double x = 0.5 * spacing - width / 2; x < width / 2; x += spacing)
    for (double y = 0.5 * spacing - height / 2; y < height / 2; y += spacing)
    {
      BlockInfo info;
      info.valid = info.planar = true;
      info.centroid = Eigen::Vector3d(x, y, depth + 0.5 * curvature * x * x + scatter * noise(random));
      info.centroid_variance = model_sigma * model_sigma;
      info.normal = Eigen::Vector3d(curvature * x, 0.0, -1.0).normalized();
      info.normal_tolerance = 0.01;
      blocks.push_back(info);
    }
  return blocks;
}

bool curved(const std::vector<BlockInfo>& info, bool by_normals)
{
  const NormalEstimator grid;
  const BlockRegionGrower grower(grid, info, DetectorParams());
  std::vector<int> blocks(info.size());
  for (size_t b = 0; b < info.size(); ++b) blocks[b] = static_cast<int>(b);
  double mean_depth = 0.0;
  for (const BlockInfo& i : info) mean_depth += i.centroid.z() / info.size();
  const Eigen::Vector3d normal(0.0, 0.0, -1.0);
  return by_normals ? grower.normalsTurn(blocks, normal) : grower.centroidsBend(blocks, normal, mean_depth);
}
}  // namespace

TEST(BlockRegions, ABendThatMovesNoPointAMillimetreIsStillAPlane)
{
  // A box lid at 0.7 m doming at 3 /m over 5 cm sags 0.9 mm: a plane. The same bend over 20 cm
  // sags 15 mm, and a can's side (3.3 cm radius) over 3 cm sags 3.4 mm: both curved, by either test.
  for (bool by_normals : {false, true})
  {
    EXPECT_FALSE(curved(bentPatch(3.0, 0.05, 0.05, 0.7), by_normals)) << by_normals;
    EXPECT_TRUE(curved(bentPatch(3.0, 0.20, 0.05, 0.7), by_normals)) << by_normals;
    EXPECT_TRUE(curved(bentPatch(1.0 / 0.033, 0.03, 0.08, 0.7), by_normals)) << by_normals;
    EXPECT_FALSE(curved(bentPatch(0.0, 0.20, 0.05, 0.7), by_normals)) << by_normals;
  }
}

TEST(BlockRegions, ABendTheNoiseModelHidesShowsInTheRegionsOwnScatter)
{
  // A cylinder's tangent strip 2.6 m away (radius 0.35 m, 14 cm wide, 50 cm tall, sag 7 mm) in
  // blocks of 3.4 cm (8 px there): the noise model gives each centroid 5.4 mm, while they
  // scatter by 1 mm (rendered quantization averages out over a block). Against the model the bend
  // is not significant; against the region's own scatter it is.
  const double depth = 2.6, spacing = 0.034, model_sigma = 0.0054, scatter = 0.001;
  EXPECT_TRUE(curved(bentPatch(1.0 / 0.35, 0.14, 0.5, depth, spacing, model_sigma, scatter), false));
  // No bend, or a bow of 3.5 mm (3 /m across 10 cm: within kSurfaceWarp, as cardboard bows), is
  // a plane however little the blocks scatter (here a 1 m tall face scattering by 0.5 mm, whose
  // bow the scatter shows clearly).
  EXPECT_FALSE(curved(bentPatch(0.0, 0.14, 0.5, depth, spacing, model_sigma, scatter), false));
  EXPECT_FALSE(curved(bentPatch(3.0, 0.10, 1.0, depth, spacing, model_sigma, 0.5 * scatter), false));
}

TEST(BlockComponents, SplitsASetIntoItsFourConnectedPiecesInTheOrderOfTheirFirstBlock)
{
  // A 5 x 4 grid: an L of four blocks (A), a pair (B) and a block touching both only across
  // corners (C).
  //   . . . . .
  //   A . . B B
  //   A . C . .
  //   A A . . .
  const int bx = 5, by = 4;
  const std::vector<int> blocks{8, 9, 5, 10, 15, 16, 12};  // B, then A, then C
  BlockComponents components;
  std::vector<std::vector<int>> found;
  for (int pass = 0; pass < 2; ++pass)  // the marks of the first call must not leak into the second
  {
    found.clear();
    components.forEach(blocks, bx, by, [&](const std::vector<int>& component) {
      std::vector<int> sorted = component;
      std::sort(sorted.begin(), sorted.end());
      found.push_back(sorted);
    });
    ASSERT_EQ(found.size(), 3u) << "pass " << pass;
    EXPECT_EQ(found[0], (std::vector<int>{8, 9}));
    EXPECT_EQ(found[1], (std::vector<int>{5, 10, 15, 16}));
    EXPECT_EQ(found[2], (std::vector<int>{12}));
  }
  // Two blocks of the L with the one between them left out are two pieces.
  found.clear();
  components.forEach({5, 15}, bx, by, [&](const std::vector<int>& component) { found.push_back(component); });
  EXPECT_EQ(found.size(), 2u);
}

TEST(BlockMarks, EmptiesOnClearAndTakesEachBlockOnce)
{
  BlockMarks marks;
  marks.clear(6);
  EXPECT_FALSE(marks.contains(2));
  EXPECT_TRUE(marks.insertNew(2));
  EXPECT_FALSE(marks.insertNew(2));
  marks.insert(4);
  EXPECT_TRUE(marks.contains(2));
  EXPECT_TRUE(marks.contains(4));
  EXPECT_FALSE(marks.contains(3));
  marks.clear(10);  // a larger grid: old and new blocks alike start out
  for (int b = 0; b < 10; ++b) EXPECT_FALSE(marks.contains(b)) << b;
}
