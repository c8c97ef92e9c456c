// The team that shares a frame's measurement: every item once, and the measurement it shares
// the same to the last bit whatever the team's size.
#include <gtest/gtest.h>

#include <atomic>
#include <vector>

#include "hough_plane_detector/core/frame_data.h"
#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/core/thread_team.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

TEST(ThreadTeam, EveryIndexIsWorkedOnceForAnyTeamSizeAndAgain)
{
  for (int members : {1, 2, 3})
  {
    ThreadTeam team(members);
    for (int n : {0, 1, 2, 7, 60, 1000})
      for (int repeat = 0; repeat < 3; ++repeat)  // the helpers come back for each call
      {
        std::vector<std::atomic<int>> visits(n);
        std::vector<std::atomic<int>> by_member(members);
        team.forEach(n, [&](int index, int member) {
          ASSERT_GE(member, 0);
          ASSERT_LT(member, members);
          visits[index].fetch_add(1);
          by_member[member].fetch_add(1);
        });
        for (int i = 0; i < n; ++i) EXPECT_EQ(visits[i].load(), 1) << "index " << i << " of " << n << ", team of " << members;
        int total = 0;
        for (auto& count : by_member) total += count.load();
        EXPECT_EQ(total, n);
      }
  }
}

TEST(ThreadTeam, AFramesWindowsAndBlocksAreTheSameMeasuredByOneThreadOrTwo)
{
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(12);
  const DetectorParams params;
  ThreadTeam alone(1), pair(2);
  for (int f : {0, 5, 9})
  {
    const RenderedFrame rendered = renderer.render(poses[f], KinectNoise(), 40 + f);
    const DepthNoiseModel noise(params.sensor_model, params.sensor_noise, 580.0);
    FrameData one, two;
    one.measure(rendered.view(), rendered.camera_to_world, params, noise, alone);
    two.measure(rendered.view(), rendered.camera_to_world, params, noise, pair);
    // Same windows in the same (row-major) order: the voting sums them in that order.
    ASSERT_GT(one.samples.size(), 300u);
    ASSERT_EQ(one.samples.size(), two.samples.size());
    EXPECT_EQ(one.normals.validWindows(), two.normals.validWindows());
    for (size_t i = 0; i < one.samples.size(); ++i)
    {
      ASSERT_EQ(one.samples[i].window_x, two.samples[i].window_x) << "sample " << i;
      ASSERT_EQ(one.samples[i].window_y, two.samples[i].window_y) << "sample " << i;
      ASSERT_EQ(one.samples[i].normal, two.samples[i].normal) << "sample " << i;
      ASSERT_EQ(one.samples[i].d, two.samples[i].d) << "sample " << i;
    }
    ASSERT_EQ(one.blocks.size(), two.blocks.size());
    for (size_t b = 0; b < one.blocks.size(); ++b)
    {
      ASSERT_EQ(one.moments(b).count, two.moments(b).count) << "block " << b;
      ASSERT_EQ(one.moments(b).sum, two.moments(b).sum) << "block " << b;
      ASSERT_EQ(one.blocks[b].planar, two.blocks[b].planar) << "block " << b;
      ASSERT_EQ(one.blocks[b].normal, two.blocks[b].normal) << "block " << b;
      ASSERT_EQ(one.blocks[b].region_residual, two.blocks[b].region_residual) << "block " << b;
    }
  }
}

TEST(ThreadTeam, TheDetectorsMapIsTheSameWithOneMeasurementThreadOrTwo)
{
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(20);
  DetectorParams single;
  single.measurement_threads = 1;
  DetectorParams pair;
  pair.measurement_threads = 2;
  PlaneDetector one(single), two(pair);
  for (int f = 0; f < 20; f += 2)
  {
    const RenderedFrame rendered = renderer.render(poses[f], KinectNoise(), 70 + f);
    ASSERT_TRUE(one.processFrame(rendered.view(), rendered.camera_to_world, 0.1 * f));
    ASSERT_TRUE(two.processFrame(rendered.view(), rendered.camera_to_world, 0.1 * f));
  }
  const auto a = one.planes(), b = two.planes();
  ASSERT_GE(a.size(), 4u);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i)
  {
    EXPECT_EQ(a[i].id, b[i].id);
    EXPECT_EQ(a[i].normal, b[i].normal) << "plane " << a[i].id;
    EXPECT_EQ(a[i].d, b[i].d) << "plane " << a[i].id;
    EXPECT_EQ(a[i].support, b[i].support) << "plane " << a[i].id;
  }
}
