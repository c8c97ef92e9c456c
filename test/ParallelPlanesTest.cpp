// The parallel-plane search on a rendered frame.
#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/core/frame_planes.h"
#include "hough_plane_detector/core/parallel_planes.h"
#include "frame_fixture.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

TEST(ParallelPlanes, FindsTheStepFromTheFloorsNormalAndMeasuresTheMapsFloorAgain)
{
  Frame f;
  DetectedPlane floor;
  floor.normal = Eigen::Vector3d::UnitZ();
  floor.d = 0.0;
  auto count = [](const std::vector<FramePlane>& planes, double height) {
    int n = 0;
    for (const FramePlane& plane : planes)
      if (std::abs(std::abs(plane.d) - height) < 0.01 && std::abs(std::abs(plane.normal.z()) - 1.0) < 1e-9 && plane.parallel)
        ++n;
    return n;
  };
  // The floor from the map: a cluster on it measures it in this frame, the step is new.
  std::vector<FramePlane> planes;
  std::vector<PlaneCandidate> candidates;
  findParallelPlanes(f.params, f.param, f.frame, f.tests, {floor}, planes, candidates);
  EXPECT_EQ(count(planes, 0.2), 1);
  EXPECT_EQ(count(planes, 0.0), 1);
  // The floor found earlier in this frame is not found twice.
  Frame g;
  FramePlane frame_floor;
  frame_floor.normal = floor.normal;
  frame_floor.d = 0.0;
  planes.assign(1, frame_floor);
  findParallelPlanes(g.params, g.param, g.frame, g.tests, {}, planes, candidates);
  EXPECT_EQ(count(planes, 0.2), 1);
  EXPECT_EQ(count(planes, 0.0), 0);
  // Nothing is found without a known direction, or with the search off.
  planes.clear();
  findParallelPlanes(f.params, f.param, f.frame, f.tests, {}, planes, candidates);
  EXPECT_TRUE(planes.empty());
  f.params.parallel_support = 0;
  findParallelPlanes(f.params, f.param, f.frame, f.tests, {floor}, planes, candidates);
  EXPECT_TRUE(planes.empty());
}
