// Test data the tests make themselves: a rosbag of the simulated office tour with tf, and the
// parsing of detect_planes' JSON lines.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/master.h>
#include <ros/ros.h>
#include <Eigen/Geometry>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include "hough_plane_detector/ros/depth_camera_publisher.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "wait_until.h"

namespace hough_plane_detector
{
namespace test
{

// A driver-like cloud: x y z, 4 bytes padding, rgb, 12 more bytes: point_step 32.
inline sensor_msgs::PointCloud2 toCloudMessage(const RenderedFrame& frame, const std::string& frame_id, double stamp)
{
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = frame_id;
  msg.header.stamp.fromSec(stamp);
  msg.width = frame.width;
  msg.height = frame.height;
  msg.point_step = 32;
  msg.row_step = msg.point_step * msg.width;
  msg.is_dense = false;
  const char* names[4] = {"x", "y", "z", "rgb"};
  const uint32_t offsets[4] = {0, 4, 8, 16};
  for (int i = 0; i < 4; ++i)
  {
    sensor_msgs::PointField f;
    f.name = names[i];
    f.offset = offsets[i];
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    msg.fields.push_back(f);
  }
  msg.data.assign(static_cast<size_t>(msg.row_step) * msg.height, 0);
  for (size_t i = 0; i < static_cast<size_t>(frame.width) * frame.height; ++i)
  {
    std::memcpy(&msg.data[i * 32], &frame.xyz[i * 3], 12);
    const float rgb = 1.0f;
    std::memcpy(&msg.data[i * 32 + 16], &rgb, 4);
  }
  return msg;
}

inline geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& t, const std::string& parent,
                                            const std::string& child, double stamp)
{
  geometry_msgs::TransformStamped msg;
  msg.header.frame_id = parent;
  msg.header.stamp.fromSec(stamp);
  msg.child_frame_id = child;
  msg.transform.translation.x = t.translation().x();
  msg.transform.translation.y = t.translation().y();
  msg.transform.translation.z = t.translation().z();
  const Eigen::Quaterniond q(t.linear());
  msg.transform.rotation.x = q.x();
  msg.transform.rotation.y = q.y();
  msg.transform.rotation.z = q.z();
  msg.transform.rotation.w = q.w();
  return msg;
}

// The usual Kinect tree: odom -> camera_link (moving) -> camera_depth_optical_frame (static).
// `tf_for_frame(f)` decides whether frame f gets its odometry transform.
inline void writeBag(const std::string& path, int frames, bool (*tf_for_frame)(int))
{
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(40);
  Eigen::Isometry3d link_to_optical = Eigen::Isometry3d::Identity();
  link_to_optical.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // optical z forward = link x
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  tf2_msgs::TFMessage static_tf;
  static_tf.transforms.push_back(toTransform(link_to_optical, "camera_link", "camera_depth_optical_frame", 100.0));
  bag.write("/tf_static", ros::Time(100.0), static_tf);
  KinectNoise noise;
  noise.coefficient = 0.5;
  for (int f = 0; f < frames; ++f)
  {
    const double stamp = 100.0 + 0.1 * f;
    const RenderedFrame frame = renderer.render(poses[f], noise, f);
    bag.write("/camera/depth/points", ros::Time(stamp), toCloudMessage(frame, "camera_depth_optical_frame", stamp));
    if (!tf_for_frame(f)) continue;
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(toTransform(poses[f] * link_to_optical.inverse(), "odom", "camera_link", stamp));
    bag.write("/tf", ros::Time(stamp + 0.01), tf);  // tf after the cloud, as in real bags
  }
  // A last transform half a second on: rosbag play may exit before its final messages are
  // delivered, and the last cloud needs its transform.
  if (frames > 0 && tf_for_frame(frames - 1))
  {
    const double stamp = 100.0 + 0.1 * (frames - 1) + 0.5;
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(toTransform(poses[frames - 1] * link_to_optical.inverse(), "odom", "camera_link", stamp));
    bag.write("/tf", ros::Time(stamp), tf);
  }
  bag.close();
}

// A recording in the TUM RGB-D layout: 32FC1 depth images in metres with NaN holes, their
// camera_info, tf1-era frame ids with a leading '/'.
constexpr double kTumStart = 1305031102.175304;  // a freiburg1 recording's first stamp
constexpr int kTumFrames = 12;

inline sensor_msgs::Image toDepthImage(const RenderedFrame& frame, const std::string& frame_id, double stamp)
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

inline sensor_msgs::CameraInfo toCameraInfo(const CameraIntrinsics& k, const std::string& frame_id, double stamp)
{
  std_msgs::Header header;
  header.frame_id = frame_id;
  header.stamp.fromSec(stamp);
  return cameraInfoOf(k, header);
}

// /world -> /kinect (the motion capture's camera body, x forward) -> /openni_depth_optical_frame,
// everything on /tf as in TUM's bags, `frames` frames at 30 Hz from kTumStart; `change` may
// spoil each image and camera_info before they are written (bad-input tests). Returns the
// planes with 20,000 points in the last frame.
inline std::vector<TruePlane> writeTumBag(
    const std::string& path, int frames,
    const std::function<void(sensor_msgs::Image&, sensor_msgs::CameraInfo&)>& change = nullptr)
{
  const SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(40);
  Eigen::Isometry3d body_to_optical = Eigen::Isometry3d::Identity();
  body_to_optical.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  std::vector<TruePlane> seen;
  KinectNoise noise;
  noise.coefficient = 0.5;
  for (int f = 0; f < frames; ++f)
  {
    const double stamp = kTumStart + f / 30.0;
    const RenderedFrame frame = renderer.render(poses[f], noise, 500 + f);
    seen.clear();
    for (size_t t = 0; t < renderer.truePlanes().size(); ++t)
      if (frame.visible_points[t] >= 20000) seen.push_back(renderer.truePlanes()[t]);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(toTransform(poses[f] * body_to_optical.inverse(), "/world", "/kinect", stamp));
    tf.transforms.push_back(toTransform(body_to_optical, "/kinect", "/openni_depth_optical_frame", stamp));
    bag.write("/tf", ros::Time(stamp), tf);
    sensor_msgs::Image image = toDepthImage(frame, "/openni_depth_optical_frame", stamp);
    sensor_msgs::CameraInfo info = toCameraInfo(renderer.intrinsics(), "/openni_depth_optical_frame", stamp);
    if (change) change(image, info);
    bag.write("/camera/depth/image", ros::Time(stamp), image);
    bag.write("/camera/depth/camera_info", ros::Time(stamp), info);
  }
  // Transforms a little later, so the last image is not left waiting when play exits.
  tf2_msgs::TFMessage tf;
  const double last = kTumStart + (frames - 1) / 30.0 + 0.5;
  tf.transforms.push_back(toTransform(poses[frames - 1] * body_to_optical.inverse(), "/world", "/kinect", last));
  tf.transforms.push_back(toTransform(body_to_optical, "/kinect", "/openni_depth_optical_frame", last));
  bag.write("/tf", ros::Time(last), tf);
  bag.close();
  return seen;
}

// main() of a rostest gtest that plays bags: gtest, a ROS node named `name`, one spinner thread.
inline int runRosTests(int argc, char** argv, const char* name)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, name);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}

// Whether the master lists at least one subscriber of `topic` (a node that will connect to
// whoever publishes it, as rosbag play's publishers).
inline bool hasSubscriber(const std::string& topic)
{
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, false)) return false;
  XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i)
    if (static_cast<std::string>(subscribers[i][0]) == topic) return subscribers[i][1].size() > 0;
  return false;
}

// Runs a shell command; its stdout and stderr, and its exit code (-1 when it did not exit).
inline std::string runCommand(const std::string& command, int* exit_code)
{
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  std::string output;
  char buffer[4096];
  while (pipe && fgets(buffer, sizeof(buffer), pipe)) output += buffer;
  const int status = pipe ? pclose(pipe) : -1;
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return output;
}

// Plays `bag` with its clock, its publishers connected to before the first message (-d 2), and
// keeps them up (-k) until `done` holds or `seconds` pass, then stops the player. When rosbag
// play exits by itself it can drop the messages still queued for a subscriber: on a busy
// machine the last cloud's transform was lost and with it the last frame. Returns whether
// `done` held and, in `exit_code`, the player's (0: it stopped as asked).
template <class Done>
bool playBagUntil(const std::string& bag, Done done, double seconds, int* exit_code)
{
  const pid_t player = fork();
  if (player == 0)
  {
    execl("/usr/lib/rosbag/play", "play", "--clock", "-d", "2", "-k", "-q", bag.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const bool held = player > 0 && waitUntil(done, seconds);
  int status = 0;
  if (player > 0)
  {
    kill(player, SIGINT);
    waitpid(player, &status, 0);
  }
  // rosbag play ends on SIGINT with 0, or is killed by it before its handler is installed.
  *exit_code = player > 0 && (WIFEXITED(status) || WIFSIGNALED(status)) ? (WIFEXITED(status) ? WEXITSTATUS(status) : 0) : -1;
  return held;
}

struct JsonPlane
{
  Eigen::Vector3d normal;
  double d;
  double area = 0.0;  // of its outlines (m^2), 0 when it has none
  size_t boundary_corners = 0;
};

// The frames of detect_planes' JSON lines (other lines, such as warnings, are skipped).
inline std::vector<std::vector<JsonPlane>> parseFrames(const std::string& output, std::vector<std::string>* frame_ids = nullptr)
{
  std::vector<std::vector<JsonPlane>> frames;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line))
  {
    const nlohmann::json frame = nlohmann::json::parse(line, nullptr, false);
    if (frame.is_discarded() || !frame.is_object() || !frame.contains("planes")) continue;
    if (frame_ids) frame_ids->push_back(frame.at("frame_id").get<std::string>());
    std::vector<JsonPlane> planes;
    for (const auto& p : frame.at("planes"))
    {
      JsonPlane plane{Eigen::Vector3d(p.at("normal")[0].get<double>(), p.at("normal")[1].get<double>(),
                                      p.at("normal")[2].get<double>()),
                      p.at("d").get<double>()};
      if (p.contains("outlines"))
        for (const auto& region : p.at("outlines"))
        {
          plane.area += region.at("area").get<double>();
          plane.boundary_corners += region.at("boundary").size();
        }
      planes.push_back(plane);
    }
    frames.push_back(planes);
  }
  return frames;
}

}  // namespace test
}  // namespace hough_plane_detector
