// Extents as shapes: each connected region's outline (concave where the region is) and holes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hough_plane_detector/core/plane_extent.h"

using namespace hough_plane_detector;

namespace
{
const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

// Marks the floor z = 0 wherever `inside(x, y)` holds, on a `step` m lattice of 5 cm cell
// centres over [x0, x1] x [y0, y1].
template <class Inside>
void markFloor(PlaneExtent& extent, double x0, double x1, double y0, double y1, double step, Inside inside)
{
  const double centre = 0.5 * PlaneExtent::kCellSize;
  for (int i = 0; x0 + centre + i * step < x1; ++i)
    for (int j = 0; y0 + centre + j * step < y1; ++j)
    {
      const double x = x0 + centre + i * step, y = y0 + centre + j * step;
      if (inside(x, y)) extent.add(Eigen::Vector3d(x, y, 0.0), kUp, 0.0, 1, 0.0f);
    }
}

// Twice the signed area about the normal: > 0 counter-clockwise.
double orientation(const std::vector<Eigen::Vector3d>& loop)
{
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < loop.size(); ++i) sum += loop[i].cross(loop[(i + 1) % loop.size()]);
  return sum.dot(kUp);
}
}  // namespace

TEST(PlaneExtent, AFloorAroundAPillarHasAnOutlineAndAHole)
{
  PlaneExtent floor;
  markFloor(floor, 0.0, 2.0, 0.0, 2.0, 0.05, [](double x, double y) { return !(x > 0.8 && x < 1.2 && y > 0.8 && y < 1.2); });
  const std::vector<PlaneOutline> shapes = floor.outlines(1, 0.0f);
  ASSERT_EQ(shapes.size(), 1u);
  const PlaneOutline& shape = shapes[0];
  EXPECT_EQ(shape.boundary.size(), 4u);  // a square: corners only
  ASSERT_EQ(shape.holes.size(), 1u);
  EXPECT_EQ(shape.holes[0].size(), 4u);
  EXPECT_GT(orientation(shape.boundary), 0.0);
  EXPECT_LT(orientation(shape.holes[0]), 0.0);
  EXPECT_NEAR(shape.area, 4.0 - 0.16, 0.02);
  // The fill covers the floor but not the pillar.
  double filled = 0.0;
  for (const auto& quad : shape.fill) filled += (quad[1] - quad[0]).cross(quad[3] - quad[0]).norm();
  EXPECT_NEAR(filled, shape.area, 1e-9);
  // The convex hull per region knows nothing of the hole.
  EXPECT_EQ(floor.regions(1, 0.0f).size(), 1u);
}

TEST(PlaneExtent, AnLShapedRegionKeepsItsConcaveCorner)
{
  PlaneExtent floor;
  markFloor(floor, 0.0, 2.0, 0.0, 2.0, 0.05, [](double x, double y) { return x < 1.0 || y < 1.0; });
  const std::vector<PlaneOutline> shapes = floor.outlines(1, 0.0f);
  ASSERT_EQ(shapes.size(), 1u);
  EXPECT_EQ(shapes[0].boundary.size(), 6u);
  EXPECT_TRUE(shapes[0].holes.empty());
  EXPECT_NEAR(shapes[0].area, 3.0, 0.02);
}

TEST(PlaneExtent, TwoTablesAreTwoShapesAndASparseWallIsOne)
{
  PlaneExtent tops;
  markFloor(tops, 0.0, 3.0, 0.0, 1.0, 0.05, [](double x, double) { return x < 1.0 || x > 2.0; });
  const std::vector<PlaneOutline> two = tops.outlines(1, 0.0f);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_NEAR(two[0].area, 1.0, 0.02);
  EXPECT_NEAR(two[1].area, 1.0, 0.02);
  // Far blocks mark every other cell: the gaps the regions bridge are closed, no lattice of holes.
  PlaneExtent sparse;
  markFloor(sparse, 0.0, 1.0, 0.0, 1.0, 0.1, [](double, double) { return true; });
  const std::vector<PlaneOutline> one = sparse.outlines(1, 0.0f);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_TRUE(one[0].holes.empty());
  EXPECT_EQ(one[0].boundary.size(), 4u);
}

TEST(PlaneExtent, ASweptExtentKeepsItsLiveCellsAndAddsToTheRightOnes)
{
  // Two cells that fade out, then one marked again in the frame of the sweep: the sweep moves
  // the live cell within the extent's storage, and later marks must still find it.
  PlaneExtent extent;
  const float fade = 0.05f;
  const Eigen::Vector3d faded_a(0.025, 0.025, 0.0), faded_b(1.025, 0.025, 0.0), live(2.025, 0.025, 0.0);
  for (const Eigen::Vector3d& p : {faded_a, faded_b, live}) extent.add(p, kUp, 0.0, 0, fade);
  extent.add(live, kUp, 0.0, 30, fade);  // 1 - 30 x 0.05 < 0: restarts at 1
  extent.sweep(30, fade);
  ASSERT_EQ(extent.cellCount(), 1u);
  extent.add(live, kUp, 0.0, 31, fade);
  extent.add(Eigen::Vector3d(3.025, 0.025, 0.0), kUp, 0.0, 31, fade);
  extent.sweep(31, fade);
  // cells() orders by the extent's own in-plane axes: tell the two apart by their weights.
  auto cells = extent.cells();
  ASSERT_EQ(cells.size(), 2u);
  std::sort(cells.begin(), cells.end(), [](const auto& a, const auto& b) { return a.second.weight > b.second.weight; });
  EXPECT_NEAR(cells[0].second.weight, 1.0f - fade + 1.0f, 1e-6);  // the live cell, marked three times
  EXPECT_NEAR(cells[1].second.weight, 1.0f, 1e-6);
  EXPECT_EQ(cells[0].second.seen, 31);
  EXPECT_EQ(cells[1].second.seen, 31);
}
