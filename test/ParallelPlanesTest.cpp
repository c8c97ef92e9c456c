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

// The step's front and the wall face the camera; a wall known 0.002 rad off: the noise model
// cannot tell that normal from the front's, the front's own scatter can. With the world's up
// known the search along a normal off the vertical leaves the front to the regions; with up
// unknown it takes it. The floor's direction, level, is searched as before either way.
TEST(ParallelPlanes, OffTheVerticalAClusterMustFitTheKnownNormalWithinItsOwnScatter)
{
  for (int up_known = 0; up_known <= 1; ++up_known)
  {
    Frame f;
    f.params.world_z_up = up_known;
    const TruePlane& wall = f.renderer.truePlanes()[f.truePlane("wall")];
    DetectedPlane known_wall, known_floor;
    known_wall.normal = Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitZ()) * wall.normal;
    known_wall.d = wall.d;
    known_floor.normal = Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitZ();
    known_floor.d = 0.0;
    std::vector<FramePlane> planes;
    std::vector<PlaneCandidate> candidates;
    findParallelPlanes(f.params, f.param, f.frame, f.tests, {known_wall, known_floor}, planes, candidates);
    int along_wall = 0, along_floor = 0;
    for (const FramePlane& plane : planes)
    {
      along_wall += std::abs(plane.normal.dot(known_wall.normal)) > 1.0 - 1e-9 && plane.support > 10000;
      along_floor += std::abs(plane.normal.dot(known_floor.normal)) > 1.0 - 1e-9 && std::abs(std::abs(plane.d) - 0.2) < 0.01;
    }
    EXPECT_EQ(along_wall, up_known ? 0 : 1) << "world_z_up " << up_known;
    EXPECT_EQ(along_floor, 1) << "world_z_up " << up_known << ": the step's top";
  }
}

// A wall 2.5 m ahead, searched along its normal known from the map, 5 cm off; a panel 1.2 m
// wide stands 15 mm proud of its middle. Each is flat, both lie within the slab of one
// cluster, and the panel in the middle leaves their joint fit untilted; but their blocks lie
// 7 and 8 mm off the cluster's plane, beyond their noise (mean centroid chi^2 beyond the bound
// noise reaches once in a hundred): refused, not reported between the two. Without the panel
// the wall is found.
TEST(ParallelPlanes, AClusterMustLieOnOnePlaneWithinItsNoise)
{
  for (bool panel : {true, false})
  {
    Scene scene;
    scene.addRectangle(Eigen::Vector3d(2.5, 0, 1.2), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 2.5, 1.2, "wall");
    if (panel)
      scene.addRectangle(Eigen::Vector3d(2.485, 0.0, 1.2), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 0.6, 1.2,
                         "panel");
    Frame f(scene, lookAt(Eigen::Vector3d(0, 0, 1.2), Eigen::Vector3d(2.5, 0, 1.2)));
    DetectedPlane wall;  // an earlier measurement, 5 cm off
    wall.normal = Eigen::Vector3d::UnitX();
    wall.d = -2.55;
    std::vector<FramePlane> planes;
    std::vector<PlaneCandidate> candidates;
    findParallelPlanes(f.params, f.param, f.frame, f.tests, {wall}, planes, candidates);
    int found = 0, refused = 0;
    for (const FramePlane& plane : planes)
      found += std::abs(std::abs(plane.normal.x()) - 1.0) < 1e-9 && std::abs(std::abs(plane.d) - 2.5) < 0.02;
    for (const PlaneCandidate& candidate : candidates)
      refused += candidate.verdict == CandidateVerdict::kCentroidsOffPlane &&
                 std::abs(std::abs(candidate.normal.x()) - 1.0) < 1e-9 && std::abs(std::abs(candidate.d) - 2.5) < 0.02;
    EXPECT_EQ(found, panel ? 0 : 1) << (panel ? "with" : "without") << " the panel";
    EXPECT_EQ(refused, panel ? 1 : 0) << (panel ? "with" : "without") << " the panel";
  }
}
