// Every kind of broken cloud is refused by the running nodelet, which keeps its map and goes on.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <mutex>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/transform_broadcaster.h>

#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "reconfigure_request.h"
#include "wait_until.h"

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

int diagnosticInt(const std::string& key)
{
  const std::string value = diagnosticValue(key);
  return value.empty() ? -1 : std::stoi(value);
}

// Good clouds (stamped `age` seconds ago) every 0.3 s until `done`: the first may arrive before
// the node's tf buffer holds the static camera transform (or, after a reset, holds it again)
// and be skipped, so no fixed wait can be long enough on a loaded machine.
// A cloud published just before `done` held may still be on its way: it returns once no plane
// array has arrived for a second.
bool publishGoodCloudsUntil(ros::Publisher& pub, double seconds, const std::function<bool()>& done, double age = 0.0)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  bool met = false;
  while (!met && ros::WallTime::now() < end)
  {
    sensor_msgs::PointCloud2 good = goodCloud();
    good.header.stamp = ros::Time::now() - ros::Duration(age);
    pub.publish(good);
    met = test::waitUntil(done, 0.3);
  }
  size_t count = arrayCount();
  ros::WallTime last_change = ros::WallTime::now();
  while (ros::WallTime::now() - last_change < ros::WallDuration(1.0) && ros::WallTime::now() < end + ros::WallDuration(10.0))
  {
    ros::WallDuration(0.05).sleep();
    if (arrayCount() != count) count = arrayCount(), last_change = ros::WallTime::now();
  }
  return met || done();
}

bool wallInMap()
{
  std::lock_guard<std::mutex> lock(mutex);
  return !arrays.empty() && arrays.back()->planes.size() == 1;
}
}  // namespace

TEST(BadInput, RefusedClouds)
{
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("/bad_input/points", 20);
  ASSERT_TRUE(test::waitUntil([&] { return pub.getNumSubscribers() > 0; }, 20.0));

  // Good frames until three were processed and the wall is in the map.
  ASSERT_TRUE(publishGoodCloudsUntil(pub, 20.0, [&] { return diagnosticInt("frames processed") >= 3 && wallInMap(); }))
      << "the wall was not found from good clouds";
  PlaneArray before;
  {
    std::lock_guard<std::mutex> lock(mutex);
    before = *arrays.back();
  }
  const size_t published_before = arrayCount();
  // Good clouds that came before the static transform were skipped: counted from the second
  // diagnostics report after the wall (the first may predate a skip).
  size_t reports = 0;
  {
    std::lock_guard<std::mutex> lock(mutex);
    reports = diagnostics.size();
  }
  ASSERT_TRUE(test::waitUntil([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return diagnostics.size() >= reports + 2;
  }, 10.0)) << "no diagnostics";
  const int skipped_before = diagnosticInt("frames skipped (no transform)");

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
  EXPECT_TRUE(test::waitUntil([&] { return diagnosticValue("frames refused (bad cloud)") == std::to_string(bad.size()); }, 10.0))
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
  ASSERT_TRUE(test::waitUntil([&] { return arrayCount() >= published_before + 2; }, 20.0));
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
  EXPECT_TRUE(test::waitUntil([&] { return diagnosticInt("frames skipped (no transform)") == skipped_before + 2; }, 15.0))
      << "skipped count " << diagnosticValue("frames skipped (no transform)") << ", " << skipped_before << " before";
}

// odom -> camera as the static publisher of the launch file gives it, under another child name.
geometry_msgs::TransformStamped cameraTransform(const std::string& child, const ros::Time& stamp)
{
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = "odom";
  t.child_frame_id = child;
  t.transform.translation.z = 1.0;
  t.transform.rotation.x = -0.5;
  t.transform.rotation.y = 0.5;
  t.transform.rotation.z = -0.5;
  t.transform.rotation.w = 0.5;
  return t;
}

TEST(BadInput, BrokenTransformsTimeJumpsAndOutOfRangeReconfigure)
{
  const std::string node = "/hough_plane_detector";
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("/bad_input/points", 20);
  ASSERT_TRUE(test::waitUntil([&] { return pub.getNumSubscribers() > 0; }, 20.0));
  ASSERT_TRUE(publishGoodCloudsUntil(pub, 20.0, [&] { return diagnosticInt("frames processed") >= 2 && wallInMap(); }));
  PlaneArray before;
  {
    std::lock_guard<std::mutex> lock(mutex);
    before = *arrays.back();
  }
  const size_t published_before = arrayCount();
  const int skipped_before = diagnosticInt("frames skipped (no transform)");
  tf2_ros::TransformBroadcaster broadcaster;

  // NaN in a transform: tf2 refuses it, so the camera frame stays unknown and its cloud is skipped.
  geometry_msgs::TransformStamped nan_transform = cameraTransform("camera_nan", ros::Time::now());
  nan_transform.transform.translation.x = std::numeric_limits<double>::quiet_NaN();
  broadcaster.sendTransform(nan_transform);
  ros::WallDuration(0.5).sleep();
  sensor_msgs::PointCloud2 c = goodCloud();
  c.header.frame_id = "camera_nan";
  c.header.stamp = ros::Time::now();
  pub.publish(c);
  EXPECT_TRUE(test::waitUntil([&] { return diagnosticInt("frames skipped (no transform)") >= skipped_before + 1; }, 15.0))
      << "a cloud behind a NaN transform was not skipped";

  // A stale transform: known at t0 only, so clouds stamped later need extrapolation; tf2's
  // filter holds them until newer ones push them out of its queue (size 2), then they count.
  const ros::Time t0 = ros::Time::now();
  broadcaster.sendTransform(cameraTransform("camera_stale", t0));
  ros::WallDuration(0.5).sleep();
  const int skipped_after_nan = diagnosticInt("frames skipped (no transform)");
  c.header.frame_id = "camera_stale";
  c.header.stamp = t0 + ros::Duration(0.5);
  for (int i = 0; i < 3; ++i) pub.publish(c);
  EXPECT_TRUE(test::waitUntil([&] { return diagnosticInt("frames skipped (no transform)") >= skipped_after_nan + 1; }, 15.0))
      << "no cloud needing extrapolation was counted as skipped";
  EXPECT_EQ(arrayCount(), published_before) << "a cloud without a usable transform changed the map";

  // Time jumps back 30 s (a looping bag): tf is reset, the map kept, and later clouds work,
  // so the latched static transform came back.
  ros::WallDuration(1.0).sleep();
  c = goodCloud();
  c.header.stamp = ros::Time::now() - ros::Duration(30.0);
  pub.publish(c);
  EXPECT_TRUE(test::waitUntil([&] { return diagnosticInt("time jumps back (tf reset)") == 1; }, 15.0))
      << "jumps " << diagnosticValue("time jumps back (tf reset)");
  const int processed = diagnosticInt("frames processed");
  EXPECT_TRUE(publishGoodCloudsUntil(
      pub, 15.0, [&] { return diagnosticInt("frames processed") >= processed + 1; }, 29.0))
      << "clouds after the tf reset were not processed";
  {
    std::lock_guard<std::mutex> lock(mutex);
    ASSERT_EQ(arrays.back()->planes.size(), 1u);
    EXPECT_EQ(arrays.back()->planes[0].id, before.planes[0].id) << "the map was not kept over the time jump";
  }

  // Out-of-range reconfigure values: dynamic_reconfigure clamps to the .cfg range; values the
  // detector cannot use are refused and the current ones kept.
  const auto clamped = call(node + "/set_parameters", setDouble("thinning_rate", 5.0));
  for (const auto& p : clamped.response.config.doubles)
    if (p.name == "thinning_rate") { EXPECT_DOUBLE_EQ(p.value, 0.99); }
  const auto refused = call(node + "/set_parameters", setInt("max_window_scale", 3));
  for (const auto& p : refused.response.config.ints)
    if (p.name == "max_window_scale") { EXPECT_EQ(p.value, 4); }
  const auto restored = call(node + "/set_parameters", setDouble("thinning_rate", 0.05));
  for (const auto& p : restored.response.config.doubles)
    if (p.name == "thinning_rate") { EXPECT_DOUBLE_EQ(p.value, 0.05); }
  c.header.stamp = ros::Time::now() - ros::Duration(28.0);
  const size_t published = arrayCount();
  pub.publish(c);
  EXPECT_TRUE(test::waitUntil([&] { return arrayCount() > published; }, 15.0)) << "the node stopped after reconfigure";
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
