#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/sim/plane_metrics.h"

using namespace hough_plane_detector;

TEST(PlaneMetrics, ErrorsIgnoreTheNormalsSign)
{
  const Eigen::Vector3d n(0, 0, 1);
  EXPECT_NEAR(angleError(-n, n), 0.0, 1e-12);
  EXPECT_NEAR(distanceError(-n, 0.5, n, -0.5), 0.0, 1e-12);
  EXPECT_NEAR(distanceError(n, -0.48, n, -0.5), 0.02, 1e-12);
  const Eigen::Vector3d tilted(std::sin(0.05), 0, std::cos(0.05));
  EXPECT_NEAR(angleError(tilted, n), 0.05, 1e-9);
  EXPECT_NEAR(angleError(-tilted, n), 0.05, 1e-9);
}

TEST(PlaneMetrics, CountsMissesFalseAndDuplicateDetections)
{
  std::vector<TruePlane> truth = {{{0, 0, 1}, 0.0, "floor"}, {{1, 0, 0}, -3.0, "wall"}, {{0, 1, 0}, -2.0, "hidden"}};
  const std::vector<int> visible = {50000, 3000, 100};
  std::vector<EvaluatedPlane> detections = {
    {{0, 0, -1}, 0.004},                              // floor, flipped sign, 4 mm off
    {Eigen::Vector3d(0.01, 0, 1).normalized(), 0.01},  // a duplicate of the floor
    {{0, 1, 0}, -2.01},                               // the hidden plane: real, so not false
    {{0.7071, 0.7071, 0}, 1.0},                       // nothing there
  };
  const FrameMetrics m = evaluateFrame(truth, visible, 2000, detections);
  EXPECT_EQ(m.visible, 2);
  EXPECT_EQ(m.detected, 1);
  EXPECT_NEAR(m.missRate(), 0.5, 1e-12);
  EXPECT_EQ(m.false_detections, 2);
  EXPECT_EQ(m.false_indices, (std::vector<int>{1, 3}));  // the duplicate and the empty place
  EXPECT_EQ(m.missed, (std::vector<int>{1}));
  ASSERT_EQ(m.d_errors.size(), 1u);
  EXPECT_NEAR(m.d_errors[0], 0.004, 1e-9);
  EXPECT_NEAR(m.angle_errors[0], 0.0, 1e-9);
}

TEST(PlaneMetrics, AHiddenSurfaceOnTheSamePlaneDoesNotTakeTheVisibleOnesDetection)
{
  // A shelf board hidden in this frame at nearly a visible table's height: the detection lies
  // closer to the board, yet it is the table's (the board is hidden, so it cannot count).
  std::vector<TruePlane> truth = {{{0, 0, 1}, -0.75, "table_top"}, {{0, 0, 1}, -0.77, "shelf_board"}};
  const std::vector<int> visible = {20000, 300};
  const std::vector<EvaluatedPlane> detections = {{{0, 0, 1}, -0.765}};
  const FrameMetrics m = evaluateFrame(truth, visible, 2000, detections);
  EXPECT_EQ(m.visible, 1);
  EXPECT_EQ(m.detected, 1);
  EXPECT_EQ(m.false_detections, 0);
  ASSERT_EQ(m.d_errors.size(), 1u);
  EXPECT_NEAR(m.d_errors[0], 0.015, 1e-9);
}
