// Every kind of broken cloud is refused by the running nodelet, which keeps its map and goes on.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <mutex>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/core/scene_renderer.h"

using namespace hough_plane_detector;

namespace
{
std::mutex mutex;
std::vector<PlaneArray::ConstPtr> arrays;
std::vector<diagnostic_msgs::DiagnosticArray::ConstPtr> diagnostics;

// A good organized cloud of a wall 2 m in front of the camera (odom -> camera is static).
sensor_msgs::PointCloud2 goodCloud(int width = 640, int height = 480)
{
  Scene scene;
  scene.addRectangle({3.0, 0, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 6.0, 6.0, "wall");
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 580.0 * width / 640.0;
  k.cx = (width - 1) / 2.0;
  k.cy = (height - 1) / 2.0;
  const RenderedFrame frame =
      SceneRenderer(scene, k).render(lookAt({1.0, 0.0, 1.0}, {3.0, 0.2, 1.0}), KinectNoise(), 1);
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = "camera_depth_optical_frame";
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(static_cast<size_t>(width) * height);
  msg.width = width;
  msg.height = height;
  msg.row_step = msg.point_step * width;
  sensor_msgs::PointCloud2Iterator<float> it(msg, "x");
  for (size_t i = 0; i < static_cast<size_t>(width) * height; ++i, ++it)
    for (int a = 0; a < 3; ++a) it[a] = frame.xyz[3 * i + a];
  return msg;
}

size_t arrayCount()
{
  std::lock_guard<std::mutex> lock(mutex);
  return arrays.size();
}

std::string diagnosticValue(const std::string& key)
{
  std::lock_guard<std::mutex> lock(mutex);
  if (diagnostics.empty()) return "";
  for (const auto& status : diagnostics.back()->status)
    for (const auto& kv : status.values)
      if (kv.key == key) return kv.value;
  return "";
}

bool waitFor(double seconds, const std::function<bool()>& done)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::WallTime::now() < end)
  {
    if (done()) return true;
    ros::WallDuration(0.05).sleep();
  }
  return done();
}
}  // namespace

TEST(BadInput, RefusedClouds)
{
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("/bad_input/points", 20);
  ASSERT_TRUE(waitFor(20.0, [&] { return pub.getNumSubscribers() > 0; }));
  ros::WallDuration(1.0).sleep();  // the static transform reaches the node's buffer

  // Three good frames: the wall is in the map.
  for (int i = 0; i < 3; ++i)
  {
    sensor_msgs::PointCloud2 good = goodCloud();
    good.header.stamp = ros::Time::now();
    pub.publish(good);
    ros::WallDuration(0.3).sleep();
  }
  ASSERT_TRUE(waitFor(10.0, [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return !arrays.empty() && arrays.back()->planes.size() == 1;
  })) << "the wall was not found from good clouds";
  PlaneArray before;
  {
    std::lock_guard<std::mutex> lock(mutex);
    before = *arrays.back();
  }
  const size_t published_before = arrayCount();

  std::vector<std::pair<std::string, sensor_msgs::PointCloud2>> bad;
  sensor_msgs::PointCloud2 c = goodCloud();
  c.width = 0;
  c.data.clear();
  bad.emplace_back("empty cloud", c);
  c = goodCloud();
  c.height = 1;
  c.width = 640 * 480;
  c.row_step = c.point_step * c.width;
  bad.emplace_back("unorganized cloud", c);
  c = goodCloud();
  c.fields.pop_back();  // no z
  bad.emplace_back("no z field", c);
  c = goodCloud();
  c.data.resize(c.data.size() / 2);
  bad.emplace_back("data shorter than row_step x height", c);
  c = goodCloud();
  c.row_step = 100;
  bad.emplace_back("row_step smaller than a row", c);
  c = goodCloud();
  c.point_step = 4;
  bad.emplace_back("point_step smaller than its fields", c);
  for (auto& entry : bad)
  {
    entry.second.header.stamp = ros::Time::now();
    pub.publish(entry.second);
    ros::WallDuration(0.2).sleep();
  }
  EXPECT_TRUE(waitFor(10.0, [&] { return diagnosticValue("frames refused (bad cloud)") == std::to_string(bad.size()); }))
      << "refused count " << diagnosticValue("frames refused (bad cloud)");
  EXPECT_EQ(arrayCount(), published_before) << "a refused cloud changed the published map";

  // All-NaN and Inf points: valid input with nothing in it; the map keeps its wall.
  sensor_msgs::PointCloud2 c2 = goodCloud();
  c = c2;
  for (sensor_msgs::PointCloud2Iterator<float> it(c, "x"); it != it.end(); ++it)
  {
    it[0] = std::numeric_limits<float>::quiet_NaN();
    it[2] = std::numeric_limits<float>::infinity();
  }
  c.header.stamp = ros::Time::now();
  pub.publish(c);
  // A huge cloud (2048 x 1536) of the same wall is processed like any other.
  c = goodCloud(2048, 1536);
  c.header.stamp = ros::Time::now();
  pub.publish(c);
  ASSERT_TRUE(waitFor(20.0, [&] { return arrayCount() >= published_before + 2; }));
  {
    std::lock_guard<std::mutex> lock(mutex);
    const PlaneArray& after = *arrays.back();
    ASSERT_EQ(after.planes.size(), 1u);
    EXPECT_EQ(after.planes[0].id, before.planes[0].id) << "the same wall, the same id";
    EXPECT_NEAR(after.planes[0].d, before.planes[0].d, 0.01);
  }

  // No transform for the frame, and an empty frame_id: both skipped and counted at once.
  c = goodCloud();
  c.header.frame_id = "frame_nobody_publishes";
  c.header.stamp = ros::Time::now();
  pub.publish(c);
  c.header.frame_id = "";
  pub.publish(c);
  EXPECT_TRUE(waitFor(15.0, [&] { return diagnosticValue("frames skipped (no transform)") == "2"; }))
      << "skipped count " << diagnosticValue("frames skipped (no transform)");
}

void onPlanes(const PlaneArray::ConstPtr& m)
{
  std::lock_guard<std::mutex> lock(mutex);
  arrays.push_back(m);
}

void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m)
{
  std::lock_guard<std::mutex> lock(mutex);
  diagnostics.push_back(m);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_bad_input");
  ros::NodeHandle nh;
  ros::Subscriber planes = nh.subscribe("/hough_plane_detector/planes", 50, onPlanes);
  ros::Subscriber diag = nh.subscribe("/diagnostics", 10, onDiagnostics);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
