// rosbag play --clock into the running nodelet gives the planes detect_planes finds offline.
#include <gtest/gtest.h>

#include <cstdio>
#include <mutex>

#include <ros/ros.h>

#include "hough_plane_detector/PlaneArray.h"
#include "plane_array_helpers.h"
#include "test_bags.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

namespace
{
bool always(int) { return true; }

}  // namespace

TEST(BagPlayback, NodeletOnAPlayedBagMatchesTheOfflineTool)
{
  const std::string bag = "/tmp/hough_plane_detector_playback_test.bag";
  const int frames = 12;
  writeBag(bag, frames, always);

  ros::NodeHandle private_nh("~");
  std::string detect_planes = DETECT_PLANES_BINARY;
  int code = 0;
  const std::string offline = runCommand(detect_planes + " --bag " + bag + " --topic /camera/depth/points", &code);
  ASSERT_EQ(code, 0) << offline;
  const auto expected_frames = parseFrames(offline);
  ASSERT_EQ(expected_frames.size(), static_cast<size_t>(frames)) << offline;
  const auto& expected = expected_frames.back();
  ASSERT_GE(expected.size(), 3u) << offline;

  PlaneArrayRecorder recorder;
  ASSERT_TRUE(waitUntil([&] { return recorder.connected() && hasSubscriber("/camera/depth/points"); }, 60.0))
      << "the detector never subscribed to /camera/depth/points";
  const double last_stamp = 100.0 + 0.1 * (frames - 1);
  playBagUntil(bag, [&] { return recorder.receivedStamp(last_stamp); }, 60.0, &code);
  ASSERT_EQ(code, 0) << "rosbag play failed on " << bag;

  const std::vector<PlaneArray::ConstPtr> received = recorder.received();
  std::string stamps;
  for (const auto& m : received) stamps += " " + std::to_string(m->header.stamp.toSec());
  ASSERT_EQ(received.size(), static_cast<size_t>(frames)) << "every played cloud gives one plane array; got" << stamps;
  const PlaneArray& last = *received.back();
  EXPECT_EQ(last.header.frame_id, "odom");
  EXPECT_NEAR(last.header.stamp.toSec(), last_stamp, 1e-6);
  ASSERT_EQ(last.planes.size(), expected.size()) << offline;
  for (size_t i = 0; i < expected.size(); ++i)
  {
    const Plane& p = last.planes[i];
    EXPECT_NEAR(p.normal.x, expected[i].normal.x(), 1e-4);
    EXPECT_NEAR(p.normal.y, expected[i].normal.y(), 1e-4);
    EXPECT_NEAR(p.normal.z, expected[i].normal.z(), 1e-4);
    EXPECT_NEAR(p.d, expected[i].d, 1e-4);
  }
}

int main(int argc, char** argv)
{
  return runRosTests(argc, argv, "test_bag_playback");
}
