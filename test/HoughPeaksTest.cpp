// Peak search (paper 3.4): climb, window maximum, eq. 6 sub-voxel mean, eq. 7-10 merge.
#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/hough_peaks.h"
#include "hough_plane_detector/core/hough_voting.h"

using namespace hough_plane_detector;

namespace
{
struct Space
{
  DetectorParams params;
  HoughParameterization param{params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance, 8};
  SparseHoughSpace space{param.sizeAngle(), param.sizeAngle(), param.sizeD()};
  HoughVoting voting{param, 2, 1.0};
  HoughPeakSearch search{param, 1};

  void gaussianAt(const Eigen::Vector3d& cell, float weight) { voting.addGaussian(space, param.fromCell(cell), weight, 1e9f); }
};

Eigen::Vector3i rounded(const Eigen::Vector3d& c)
{
  return Eigen::Vector3i(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())),
                         static_cast<int>(std::lround(c.z())));
}
}  // namespace

TEST(HoughPeaks, ClimbsToTheTopAndRefinesBelowACell)
{
  Space s;
  const Eigen::Vector3d centre(150.35, 210.6, 1000.2);
  s.gaussianAt(centre, 10.0f);
  const Eigen::Vector3i top = rounded(centre);
  EXPECT_EQ(s.search.climb(s.space, top + Eigen::Vector3i(2, -1, 2)), top);
  EXPECT_TRUE(s.search.isWindowMaximum(s.space, top));
  EXPECT_FALSE(s.search.isWindowMaximum(s.space, top + Eigen::Vector3i(1, 0, 0)));
  const std::vector<HoughPeak> peaks = s.search.extract(s.space, {top + Eigen::Vector3i(-2, 1, 0)}, 5.0);
  ASSERT_EQ(peaks.size(), 1u);
  // Eq. 6 over a 3^3 window leans to the top cell but halves the rounding's error at least.
  const double rounding_error = (top.cast<double>() - centre).norm();
  EXPECT_LT((s.param.toCell(peaks[0].hough) - centre).norm(), 0.5 * rounding_error);
  EXPECT_GT(peaks[0].value, 8.0);
  Eigen::Vector3d normal;
  double d;
  s.param.fromHough(peaks[0].hough, normal, d);
  EXPECT_NEAR(normal.dot(peaks[0].normal), 1.0, 1e-12);
}

TEST(HoughPeaks, APeaksHeightDoesNotDependOnWhereBetweenTheCellsItFell)
{
  // One Gaussian of weight 2 half a cell off on every axis reads 2 exp(-3/8) = 1.37 at its
  // nearest cell; its height from the cells' log values is 2 wherever it fell.
  for (const Eigen::Vector3d& offset :
       {Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(-0.3, 0.45, 0.1)})
  {
    Space s;
    const Eigen::Vector3d centre = Eigen::Vector3d(120, 130, 900) + offset;
    s.gaussianAt(centre, 2.0f);
    const Eigen::Vector3i top = s.search.climb(s.space, rounded(centre));
    EXPECT_NEAR(s.search.peakHeight(s.space, top), 2.0, 1e-4) << offset.transpose();
    // Judged by height, the peak passes 1.5; by its cell only when it fell near the centre
    // (the cell reads 2 exp(-|offset|^2 / 2) with the blur's sigma of 1 cell).
    EXPECT_EQ(s.search.extract(s.space, {top}, 1.5, {1}).size(), 1u);
    const size_t by_cell = 2.0 * std::exp(-0.5 * offset.squaredNorm()) >= 1.5 ? 1u : 0u;
    EXPECT_EQ(s.search.extract(s.space, {top}, 1.5).size(), by_cell) << offset.transpose();
  }
}

TEST(HoughPeaks, SeedsOfOnePeakGiveItOnceAndTheThresholdDropsWeakOnes)
{
  Space s;
  s.gaussianAt(Eigen::Vector3d(100, 100, 800), 10.0f);
  s.gaussianAt(Eigen::Vector3d(140, 90, 1200), 3.0f);
  const std::vector<Eigen::Vector3i> seeds{{100, 100, 800}, {101, 99, 801}, {140, 90, 1200}, {141, 90, 1199}};
  EXPECT_EQ(s.search.extract(s.space, seeds, 1.0).size(), 2u);
  // Every seed reports the top it climbed to, also those of a peak under the threshold.
  std::vector<Eigen::Vector3i> tops;
  const std::vector<HoughPeak> strong = s.search.extract(s.space, seeds, 5.0, {}, &tops);
  ASSERT_EQ(strong.size(), 1u);
  EXPECT_FLOAT_EQ(static_cast<float>(strong[0].value), 10.0f);
  ASSERT_EQ(tops.size(), seeds.size());
  EXPECT_EQ(tops[0], Eigen::Vector3i(100, 100, 800));
  EXPECT_EQ(tops[1], tops[0]);
  EXPECT_EQ(tops[2], Eigen::Vector3i(140, 90, 1200));
  EXPECT_EQ(tops[3], tops[2]);
}

TEST(HoughPeaks, MergeJoinsSimilarPlanesByTheirValues)
{
  Space s;
  HoughPeak a, b, far;
  a.normal = Eigen::Vector3d::UnitZ();
  a.d = -1.0;
  a.value = 3.0;
  b.normal = Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ();
  b.d = -1.02;
  b.value = 1.0;
  far = a;
  far.d = -1.5;
  far.value = 2.0;
  // b seen from the other side is still the same plane.
  HoughPeak b_flipped = b;
  b_flipped.normal = -b.normal;
  b_flipped.d = -b.d;
  const std::vector<HoughPeak> merged = mergeSimilarPeaks({b_flipped, far, a}, 0.05, 0.05, s.param);
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_EQ(merged[0].value, 3.0);  // strongest first, keeps its own value
  EXPECT_NEAR(merged[0].d, (3.0 * -1.0 + 1.0 * -1.02) / 4.0, 1e-12);
  EXPECT_NEAR(std::acos(merged[0].normal.dot(Eigen::Vector3d::UnitZ())), 0.005, 2e-4);  // a quarter of the way
  EXPECT_NEAR(merged[1].d, -1.5, 1e-12);
  // Beyond either tolerance, no merge.
  EXPECT_EQ(mergeSimilarPeaks({a, b}, 0.01, 0.05, s.param).size(), 2u);
  EXPECT_EQ(mergeSimilarPeaks({a, b}, 0.05, 0.01, s.param).size(), 2u);
}
