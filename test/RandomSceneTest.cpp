#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "hough_plane_detector/sim/random_scene.h"

using namespace hough_plane_detector;

namespace
{
double degreesFromVertical(const Eigen::Vector3d& normal)
{
  return std::acos(std::min(1.0, std::abs(normal.z()))) * 180.0 / M_PI;
}
}  // namespace

TEST(RandomScene, ASeedAlwaysGivesTheSameRoomAndOthersDiffer)
{
  const RandomScene a = makeRandomScene(101, 10), again = makeRandomScene(101, 10), other = makeRandomScene(102, 10);
  ASSERT_EQ(a.scene.rectangles.size(), again.scene.rectangles.size());
  for (size_t i = 0; i < a.scene.rectangles.size(); ++i)
    EXPECT_TRUE(a.scene.rectangles[i].center.isApprox(again.scene.rectangles[i].center));
  ASSERT_EQ(a.poses.size(), 10u);
  for (size_t i = 0; i < a.poses.size(); ++i) EXPECT_TRUE(a.poses[i].isApprox(again.poses[i]));
  EXPECT_EQ(a.description, again.description);
  EXPECT_NE(a.description, other.description);
}

// The held-out lists: no seed twice, and none on the tuning or development lists.
TEST(RandomScene, HeldOutAndTuningSeedsAreDisjoint)
{
  std::set<uint32_t> held_out(kHeldOutSeeds.begin(), kHeldOutSeeds.end());
  EXPECT_GE(held_out.size(), 20u);
  for (uint32_t seed : kSecondHeldOutSeeds) EXPECT_TRUE(held_out.insert(seed).second) << "listed twice: " << seed;
  EXPECT_GE(held_out.size(), 60u);
  for (uint32_t seed : kThirdHeldOutSeeds) EXPECT_TRUE(held_out.insert(seed).second) << "listed twice: " << seed;
  EXPECT_GE(held_out.size(), 100u);
  for (const auto* tuned : {&kTuningSeeds, &kDevelopmentSeeds, &kSecondDevelopmentSeeds})
    for (uint32_t seed : *tuned) EXPECT_EQ(held_out.count(seed), 0u) << seed;
}

// Every room has its floor and walls, the camera inside looking at them within the stated
// ranges, and ramps and sloped ceilings as steep as the protocol says.
TEST(RandomScene, EveryRoomIsWithinTheProtocolsRanges)
{
  int ramps = 0, slopes = 0, stairs = 0;
  for (uint32_t seed : kHeldOutSeeds)
  {
    const RandomScene room = makeRandomScene(seed, 12);
    EXPECT_GE(room.noise, 0.5);
    EXPECT_LE(room.noise, 2.0);
    int walls = 0;
    bool floor = false;
    for (const TruePlane& plane : room.scene.truePlanes())
    {
      if (plane.name == "floor") floor = std::abs(plane.normal.z()) > 0.999 && std::abs(plane.d) < 1e-9;
      if (plane.name.rfind("wall_", 0) == 0) walls += std::abs(plane.normal.z()) < 1e-9;
      if (plane.name == "ramp")
      {
        ++ramps;
        EXPECT_GE(degreesFromVertical(plane.normal), 5.0 - 1e-6) << room.description;
        EXPECT_LE(degreesFromVertical(plane.normal), 20.0 + 1e-6) << room.description;
      }
      if (plane.name == "ceiling_slope")
      {
        ++slopes;
        EXPECT_GE(degreesFromVertical(plane.normal), 20.0 - 1e-6) << room.description;
        EXPECT_LE(degreesFromVertical(plane.normal), 45.0 + 1e-6) << room.description;
      }
      stairs += plane.name.rfind("stair", 0) == 0;
    }
    EXPECT_TRUE(floor) << seed;
    EXPECT_EQ(walls, 4) << seed;
    for (const Eigen::Isometry3d& pose : room.poses)
    {
      EXPECT_GE(pose.translation().z(), 0.8);
      EXPECT_LE(pose.translation().z(), 1.6);
    }
    // The camera sees the room: most pixels of its first frame hit something.
    const RenderedFrame frame = SceneRenderer(room.scene).render(room.poses.front(), KinectNoise(), seed);
    int valid = 0;
    for (int v = 0; v < frame.view().height; v += 8)
      for (int u = 0; u < frame.view().width; u += 8)
      {
        float x, y, z;
        frame.view().point(u, v, x, y, z);
        valid += std::isfinite(z);
      }
    EXPECT_GT(valid, 80 * 60 / 2) << room.description;
  }
  // The protocol's features all occur among the held-out rooms.
  EXPECT_GT(ramps, 0);
  EXPECT_GT(slopes, 0);
  EXPECT_GT(stairs, 0);
}
