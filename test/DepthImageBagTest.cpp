// A recording in the TUM RGB-D layout (32FC1 depth image in metres, its camera_info, tf1-era
// frame ids with a leading '/', a 2011 stamp) played through depth_image.launch:
// depth_image_proc's point_cloud_xyz and the detector in one manager find the room's planes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "hough_plane_detector/PlaneArray.h"
#include "test_bags.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

namespace
{
constexpr double kStart = 1305031102.175304;  // a freiburg1 recording's first stamp
constexpr int kFrames = 12;

sensor_msgs::Image toDepthImage(const RenderedFrame& frame, const std::string& frame_id, double stamp)
{
  sensor_msgs::Image image;
  image.header.frame_id = frame_id;
  image.header.stamp.fromSec(stamp);
  image.width = frame.width;
  image.height = frame.height;
  image.encoding = "32FC1";
  image.step = 4 * frame.width;
  image.data.resize(static_cast<size_t>(image.step) * frame.height);
  for (size_t i = 0; i < static_cast<size_t>(frame.width) * frame.height; ++i)
  {
    const float z = frame.xyz[i * 3 + 2];  // NaN where the sensor saw nothing, as TUM's bags
    std::memcpy(&image.data[i * 4], &z, 4);
  }
  return image;
}

sensor_msgs::CameraInfo toCameraInfo(const CameraIntrinsics& k, const std::string& frame_id, double stamp)
{
  sensor_msgs::CameraInfo info;
  info.header.frame_id = frame_id;
  info.header.stamp.fromSec(stamp);
  info.width = k.width;
  info.height = k.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0};
  return info;
}

// /world -> /kinect (the motion capture's camera body, x forward) -> /openni_depth_optical_frame,
// everything on /tf as in TUM's bags. Returns the planes with 20,000 points in the last frame.
std::vector<TruePlane> writeTumBag(const std::string& path)
{
  const SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(40);
  Eigen::Isometry3d body_to_optical = Eigen::Isometry3d::Identity();
  body_to_optical.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  std::vector<TruePlane> seen;
  KinectNoise noise;
  noise.coefficient = 0.5;
  for (int f = 0; f < kFrames; ++f)
  {
    const double stamp = kStart + f / 30.0;
    const RenderedFrame frame = renderer.render(poses[f], noise, 500 + f);
    seen.clear();
    for (size_t t = 0; t < renderer.truePlanes().size(); ++t)
      if (frame.visible_points[t] >= 20000) seen.push_back(renderer.truePlanes()[t]);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(toTransform(poses[f] * body_to_optical.inverse(), "/world", "/kinect", stamp));
    tf.transforms.push_back(toTransform(body_to_optical, "/kinect", "/openni_depth_optical_frame", stamp));
    bag.write("/tf", ros::Time(stamp), tf);
    bag.write("/camera/depth/image", ros::Time(stamp), toDepthImage(frame, "/openni_depth_optical_frame", stamp));
    bag.write("/camera/depth/camera_info", ros::Time(stamp),
              toCameraInfo(renderer.intrinsics(), "/openni_depth_optical_frame", stamp));
  }
  // Transforms a little later, so the last image is not left waiting when play exits.
  tf2_msgs::TFMessage tf;
  const double last = kStart + (kFrames - 1) / 30.0 + 0.5;
  tf.transforms.push_back(toTransform(poses[kFrames - 1] * body_to_optical.inverse(), "/world", "/kinect", last));
  tf.transforms.push_back(toTransform(body_to_optical, "/kinect", "/openni_depth_optical_frame", last));
  bag.write("/tf", ros::Time(last), tf);
  bag.close();
  return seen;
}
}  // namespace

TEST(DepthImage, ATumStyleBagGivesTheRoomsPlanes)
{
  const std::string bag = "/tmp/hough_plane_detector_tum_style.bag";
  const std::vector<TruePlane> truth = writeTumBag(bag);

  std::mutex mutex;
  std::vector<PlaneArray::ConstPtr> received;
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<PlaneArray>("/hough_plane_detector/planes", 100, [&](const PlaneArray::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    received.push_back(m);
  });
  ros::WallDuration(3.0).sleep();  // let the subscriptions (ours, the detector's, depth_image_proc's) connect
  int code = 0;
  const std::string played = runCommand("/usr/lib/rosbag/play --clock -d 1 " + bag, &code);
  ASSERT_EQ(code, 0) << played;
  ros::WallDuration(2.0).sleep();

  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_FALSE(received.empty()) << "no plane array: the depth images never became clouds the detector took";
  const PlaneArray& last = *received.back();
  EXPECT_EQ(last.header.frame_id, "world");
  EXPECT_NEAR(last.header.stamp.toSec(), kStart + (kFrames - 1) / 30.0, 1e-6) << "the recording's stamps are kept";
  // Every large plane of the last frame (the floor, the walls in view), once, within 0.01 rad and 2 cm.
  ASSERT_GE(truth.size(), 2u);
  for (const TruePlane& t : truth)
  {
    int matches = 0;
    for (const Plane& p : last.planes)
    {
      const Eigen::Vector3d n(p.normal.x, p.normal.y, p.normal.z);
      const double sign = n.dot(t.normal) >= 0.0 ? 1.0 : -1.0;
      matches += std::acos(std::min(1.0, std::abs(n.dot(t.normal)))) < 0.01 && std::abs(sign * p.d - t.d) < 0.02;
    }
    EXPECT_EQ(matches, 1) << t.name << " (n " << t.normal.transpose() << ", d " << t.d << ") among "
                          << last.planes.size() << " planes";
  }
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_depth_image");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
