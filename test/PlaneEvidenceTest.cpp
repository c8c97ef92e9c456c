// Forgetting by evidence (forgetting = 1) against the paper's thinning: what is out of view
// keeps its state, what the camera sees to be gone leaves.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "detector_test_helpers.h"
#include "hough_plane_detector/core/plane_evidence.h"

namespace
{
// A few noisy renderings of one pose, cycled: a still camera without rendering every frame.
std::vector<RenderedFrame> stillCamera(const SceneRenderer& renderer, const Eigen::Isometry3d& pose, uint32_t seed)
{
  std::vector<RenderedFrame> frames;
  for (uint32_t i = 0; i < 4; ++i) frames.push_back(renderer.render(pose, kinect(1.0), seed + i));
  return frames;
}

// A 7 x 4 m hall (floor, east and west walls at x = +-3.5) and a camera in its middle looking
// at one wall, then the other.
struct Hall
{
  Hall()
  {
    Scene hall;
    hall.addRectangle({0, 0, 0}, kX, kY, 6.0, 4.0, "floor");
    hall.addRectangle({3.5, 0, 1.5}, kY, kZ, 4.0, 1.5, "east");
    hall.addRectangle({-3.5, 0, 1.5}, kY, kZ, 4.0, 1.5, "west");
    const SceneRenderer renderer(hall);
    east = stillCamera(renderer, lookAt({0, 0, 1.2}, {3.5, 0.3, 0.9}), 10);
    west = stillCamera(renderer, lookAt({0, 0, 1.2}, {-3.5, -0.3, 0.9}), 20);
  }
  std::vector<RenderedFrame> east, west;
};

DetectorParams forgettingBy(int forgetting)
{
  DetectorParams params;
  params.forgetting = forgetting;
  return params;
}
}  // namespace

// A hall: the camera looks at the east wall for 15 frames, at the west wall for 1,000, then
// back. By evidence the east wall, out of view all that time, is still in the map; thinning
// loses it (paper 3.7: every cell loses thinning_rate per frame).
TEST(PlaneEvidence, ALookedAwayWallStaysForAThousandFrames)
{
  const Hall hall;
  const auto& east = hall.east;
  const auto& west = hall.west;
  for (int forgetting : {kForgetByEvidence, kForgetByThinning})
  {
    PlaneDetector detector(forgettingBy(forgetting));
    int f = 0;
    for (int i = 0; i < 15; ++i, ++f) feed(detector, east[f % 4], 0.033 * f);
    ASSERT_EQ(matching(detector.planes(), kX, -3.5, 0.01, 0.02).size(), 1u) << describe(detector.planes());
    int away_until_lost = -1;
    for (int i = 0; i < 1000; ++i, ++f)
    {
      feed(detector, west[f % 4], 0.033 * f);
      if (away_until_lost < 0 && matching(detector.planes(), kX, -3.5, 0.01, 0.02).empty()) away_until_lost = i;
    }
    EXPECT_EQ(matching(detector.planes(), kX, 3.5, 0.01, 0.02).size(), 1u) << "the west wall" << describe(detector.planes());
    if (forgetting == kForgetByEvidence)
    {
      EXPECT_EQ(away_until_lost, -1) << "the east wall left the map after " << away_until_lost << " frames away";
      const DetectedPlane* wall = matching(detector.planes(), kX, -3.5, 0.01, 0.02).front();
      EXPECT_GE(wall->confirmations, 10) << "its 15 frames in view confirmed it";
      EXPECT_EQ(wall->contradictions, 0);
    }
    else
    {
      EXPECT_GE(away_until_lost, 0) << "thinning kept the east wall: the test no longer needs forgetting by evidence";
    }
    std::printf("look-away, forgetting %d: east wall lost after %d frames away (-1: kept)\n", forgetting, away_until_lost);
    // Back: the east wall is (still, or again) there.
    for (int i = 0; i < 5; ++i, ++f) feed(detector, east[f % 4], 0.033 * f);
    EXPECT_EQ(matching(detector.planes(), kX, -3.5, 0.01, 0.02).size(), 1u) << describe(detector.planes());
  }
}

// A plane seen in fewer than PlaneBelief::kEstablishedAfter frames is not yet kept out of view:
// it fades as with thinning (a plane one glance suggested must not stay for good).
TEST(PlaneEvidence, APlaneGlimpsedTwiceFadesOutOfView)
{
  const Hall hall;
  const auto& east = hall.east;
  const auto& west = hall.west;
  PlaneDetector detector(forgettingBy(kForgetByEvidence));
  int f = 0;
  for (int i = 0; i < 2; ++i, ++f) feed(detector, east[f % 4], 0.033 * f);
  ASSERT_EQ(matching(detector.planes(), kX, -3.5, 0.01, 0.02).size(), 1u) << describe(detector.planes());
  for (int i = 0; i < 300; ++i, ++f) feed(detector, west[f % 4], 0.033 * f);
  EXPECT_TRUE(matching(detector.planes(), kX, -3.5, 0.01, 0.02).empty()) << describe(detector.planes());
  EXPECT_EQ(matching(detector.planes(), kX, 3.5, 0.01, 0.02).size(), 1u) << describe(detector.planes());
}

// A far wall seen only through a doorway, then the camera steps aside: the far wall's cells now
// lie behind the near wall (something in front: no evidence), so 300 frames do not clear it.
TEST(PlaneEvidence, AWallSeenThroughADoorwayIsNotClearedByFramesThatCannotSeeIt)
{
  Scene scene;
  scene.addRectangle({2.0, 0, 0}, kX, kY, 4.0, 4.0, "floor");
  scene.addRectangle({2.0, -2.25, 1.5}, kY, kZ, 1.75, 1.5, "near wall, left of the door");
  scene.addRectangle({2.0, 2.25, 1.5}, kY, kZ, 1.75, 1.5, "near wall, right of the door");
  scene.addRectangle({2.0, 0.0, 2.5}, kY, kZ, 0.5, 0.5, "near wall, over the door");
  scene.addRectangle({5.0, 0.0, 1.5}, kY, kZ, 1.5, 1.5, "far wall");
  const SceneRenderer renderer(scene);
  const auto through = stillCamera(renderer, lookAt({0, 0, 1.2}, {2.0, 0.0, 1.0}), 50);
  // Aside, the camera looks toward the far wall, but the near wall stands in front of it.
  const auto aside = stillCamera(renderer, lookAt({0, -3.0, 1.2}, {5.0, 0.0, 1.0}), 60);
  for (int forgetting : {kForgetByEvidence, kForgetByThinning})
  {
    PlaneDetector detector(forgettingBy(forgetting));
    int f = 0;
    for (int i = 0; i < 12; ++i, ++f) feed(detector, through[f % 4], 0.033 * f);  // below permanence_cap
    ASSERT_EQ(matching(detector.planes(), kX, -5.0, 0.01, 0.02).size(), 1u) << "far wall" << describe(detector.planes());
    for (int i = 0; i < 300; ++i, ++f) feed(detector, aside[f % 4], 0.033 * f);
    EXPECT_EQ(matching(detector.planes(), kX, -2.0, 0.01, 0.02).size(), 1u) << "near wall" << describe(detector.planes());
    const auto far = matching(detector.planes(), kX, -5.0, 0.01, 0.02);
    if (forgetting == kForgetByEvidence)
    {
      ASSERT_EQ(far.size(), 1u) << "the far wall was cleared" << describe(detector.planes());
      EXPECT_EQ(far.front()->contradictions, 0);
    }
    else
    {
      EXPECT_TRUE(far.empty()) << "thinning kept the far wall: the test no longer shows the difference";
    }
  }
}

// A still camera watches a box on the floor before a wall; at frame 40 the box is taken away.
// By evidence its top and front leave the map within 30 frames of seeing the floor and wall
// where they were, while the floor and wall stay; with thinning they stay (permanent cells).
TEST(PlaneEvidence, ATakenAwayBoxLeavesWithinThirtyFrames)
{
  Scene with_box, without_box;
  for (Scene* scene : {&with_box, &without_box})
  {
    scene->addRectangle({2.0, 0, 0}, kX, kY, 3.0, 3.0, "floor");
    scene->addRectangle({4.0, 0, 1.5}, kY, kZ, 3.0, 1.5, "wall");
  }
  with_box.addBox({2.0, 0.0, 0.25}, {0.25, 0.35, 0.25}, 0.0, "box");
  const Eigen::Isometry3d pose = lookAt({0, 0, 1.2}, {2.5, 0.0, 0.3});
  const auto before = stillCamera(SceneRenderer(with_box), pose, 30);
  const auto after = stillCamera(SceneRenderer(without_box), pose, 40);
  for (int forgetting : {kForgetByEvidence, kForgetByThinning})
  {
    PlaneDetector detector(forgettingBy(forgetting));
    int f = 0;
    for (; f < 40; ++f) feed(detector, before[f % 4], 0.033 * f);
    ASSERT_EQ(matching(detector.planes(), kZ, -0.5, 0.02, 0.02).size(), 1u) << "box top" << describe(detector.planes());
    ASSERT_EQ(matching(detector.planes(), kX, -1.75, 0.02, 0.02).size(), 1u) << "box front" << describe(detector.planes());
    int top_gone = -1, front_gone = -1;
    for (int i = 0; i < 60; ++i, ++f)
    {
      feed(detector, after[f % 4], 0.033 * f);
      if (top_gone < 0 && matching(detector.planes(), kZ, -0.5, 0.02, 0.02).empty()) top_gone = i + 1;
      if (front_gone < 0 && matching(detector.planes(), kX, -1.75, 0.02, 0.02).empty()) front_gone = i + 1;
    }
    std::printf("taken-away box, forgetting %d: top gone after %d frames, front after %d (-1: kept)\n", forgetting,
                top_gone, front_gone);
    EXPECT_EQ(matching(detector.planes(), kZ, 0.0, 0.01, 0.02).size(), 1u) << "floor" << describe(detector.planes());
    EXPECT_EQ(matching(detector.planes(), kX, -4.0, 0.01, 0.02).size(), 1u) << "wall" << describe(detector.planes());
    if (forgetting == kForgetByEvidence)
    {
      EXPECT_TRUE(top_gone > 0 && top_gone <= 30) << "box top left after " << top_gone << " frames";
      EXPECT_TRUE(front_gone > 0 && front_gone <= 30) << "box front left after " << front_gone << " frames";
    }
    else
    {
      EXPECT_TRUE(top_gone < 0 || front_gone < 0) << "thinning removed both within 60 frames: the test no longer "
                                                     "needs forgetting by evidence";
    }
  }
}

// Depths within 3 sigma + 2 cm of a plane confirm it, so they confirm a plane fitted through two
// surfaces (a box's side and the face of the box stacked on it) as readily as one surface, in
// every frame that sees them from about the same view. The map keeps a plane out of view only
// once a frame measured it as one surface (FramePlane::measuresOneSurface): here a wall's map
// plane, confirmed by its depths for ten frames, each frame's measurement of it a region that
// fits its blocks or one that does not; then the camera looks away for thirty frames.
TEST(PlaneEvidence, OnlyAPlaneMeasuredAsOneSurfaceIsKeptOutOfView)
{
  Scene scene;
  scene.addRectangle({2.0, 0, 1.0}, kY, kZ, 1.5, 1.0, "wall");
  const Eigen::Isometry3d pose = lookAt({0, 0, 1.0}, {2.0, 0, 1.0});
  const RenderedFrame seen = SceneRenderer(scene).render(pose, kinect(1.0), 7);
  const PinholeIntrinsics intrinsics = estimateIntrinsics(seen.view());
  ASSERT_TRUE(intrinsics.valid());
  const DepthNoiseModel noise(kKinectV1, 1.0, intrinsics.fx);
  // The wall's blocks as the labels would hand them to the map: one per 5 cm extent cell.
  FrameData observed;
  observed.camera_to_world = pose;
  for (double y = -1.4; y <= 1.4; y += 0.05)
    for (double z = 0.1; z <= 1.9; z += 0.05)
    {
      BlockInfo block;
      block.centroid = pose.inverse() * Eigen::Vector3d(2.0, y, z);
      observed.blocks.push_back(block);
    }
  for (bool one_surface : {true, false})
  {
    DetectorParams params;
    ASSERT_EQ(params.forgetting, kForgetByEvidence);
    const HoughParameterization param{params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance,
                                      params.blur_kernel_size / 2 + params.peak_window / 2 + 2};
    const HoughVoting voting{param, params.blur_kernel_size / 2, params.blur_sigma};
    const HoughPeakSearch search{param, params.peak_window / 2};
    PlaneMap map{params, param, voting, search};
    FramePlane wall;
    wall.normal = -kX;
    wall.d = 2.0;
    wall.hough = param.toHough(wall.normal, wall.d);
    wall.support = wall.first_sight_points = 20000;
    wall.blocks = {1, 2, 3};
    wall.fits_its_blocks = one_surface;
    wall.normal_sigma = 0.002;
    wall.offset_sigma = 0.001;
    wall.centroid = Eigen::Vector3d(2.0, 0, 1.0);
    int f = 0;
    for (; f < 10; ++f)
    {
      map.beginFrame();
      map.checkEvidence(seen.view(), pose, intrinsics, noise);
      map.accumulate({wall}, pose.translation(), f);
      ASSERT_EQ(map.planes().size(), 1u) << "frame " << f;
      map.observe({20000}, std::vector<int>(observed.blocks.size(), map.planes()[0].id), observed, f);
    }
    const PlaneBelief* belief = map.belief(map.planes()[0].id);
    ASSERT_NE(belief, nullptr);
    EXPECT_GE(belief->confirmations, PlaneBelief::kEstablishedAfter) << "its depths confirmed it";
    EXPECT_EQ(belief->established(), one_surface);
    // Looking away: no evidence and no measurement.
    for (; f < 40; ++f)
    {
      map.beginFrame();
      map.accumulate({}, pose.translation(), f);
      map.observe(std::vector<int>(map.planes().size(), 0), std::vector<int>(observed.blocks.size(), -1), observed, f);
    }
    EXPECT_EQ(map.planes().size(), one_surface ? 1u : 0u) << (one_surface ? "measured as one surface" : "never measured as one surface");
  }
}
