// A recording in the TUM RGB-D layout (32FC1 depth image in metres, its camera_info, tf1-era
// frame ids with a leading '/', a 2011 stamp) played through depth_image.launch:
// depth_image_proc's point_cloud_xyz and the detector in one manager find the room's planes.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>

#include <ros/ros.h>

#include "hough_plane_detector/PlaneArray.h"
#include "plane_array_helpers.h"
#include "test_bags.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;


TEST(DepthImage, ATumStyleBagGivesTheRoomsPlanes)
{
  const std::string bag = "/tmp/hough_plane_detector_tum_style.bag";
  const std::vector<TruePlane> truth = writeTumBag(bag, kTumFrames);

  PlaneArrayRecorder recorder;
  // depth_image_proc asks for depth images only once its cloud has a subscriber (the detector):
  // the chain is up when both inputs have a subscriber and the detector's planes reach us.
  ASSERT_TRUE(waitUntil(
      [&] {
        return recorder.connected() && hasSubscriber("/camera/depth/image") &&
               hasSubscriber("/camera/depth/camera_info");
      },
      60.0))
      << "the detector and depth_image_proc never subscribed";
  int code = 0;
  const double last_stamp = kTumStart + (kTumFrames - 1) / 30.0;
  playBagUntil(bag, [&] { return recorder.receivedStamp(last_stamp); }, 60.0, &code);
  ASSERT_EQ(code, 0) << "rosbag play failed on " << bag;

  const std::vector<PlaneArray::ConstPtr> received = recorder.received();
  ASSERT_FALSE(received.empty()) << "no plane array: the depth images never became clouds the detector took";
  const PlaneArray& last = *received.back();
  EXPECT_EQ(last.header.frame_id, "world");
  EXPECT_NEAR(last.header.stamp.toSec(), last_stamp, 1e-6) << "the recording's stamps are kept";
  // Every large plane of the last frame (the floor, the walls in view), once, within 0.01 rad and 2 cm.
  ASSERT_GE(truth.size(), 2u);
  for (const TruePlane& t : truth)
    EXPECT_EQ(matchesOf(last, t, 0.01, 0.02), 1) << t.name << " (n " << t.normal.transpose() << ", d " << t.d << ") among "
                                                 << last.planes.size() << " planes";
}

int main(int argc, char** argv)
{
  return runRosTests(argc, argv, "test_depth_image");
}
