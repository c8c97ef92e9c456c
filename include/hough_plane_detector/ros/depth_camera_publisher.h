// What a depth camera source publishes, with openni2_camera's names: depth/image_raw (16UC1,
// millimetres), depth/camera_info and the organized depth/points, one stamp and frame for all.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>

#include "hough_plane_detector/core/camera_intrinsics.h"

namespace hough_plane_detector
{

// The camera_info of an undistorted pinhole depth camera.
inline sensor_msgs::CameraInfo cameraInfoOf(const CameraIntrinsics& k, const std_msgs::Header& header)
{
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = k.width;
  info.height = k.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

// A device's frame clock mapped onto ROS time: anchored at the first frame and again whenever
// the two clocks drift 0.1 s apart (a wrapped counter, a wrong clock rate, a paused recording).
class DeviceClock
{
public:
  explicit DeviceClock(double ticks_per_second) : ticks_per_second_(ticks_per_second) {}
  ros::Time stamp(uint64_t ticks, const ros::Time& now);

private:
  double ticks_per_second_;
  bool anchored_ = false;
  uint64_t anchor_ticks_ = 0;
  ros::Time anchor_time_;
};

class DepthCameraPublisher
{
public:
  // Advertises on nh (the camera's namespace).
  void advertise(ros::NodeHandle& nh);
  // One frame of millimetre depths (0: no return), row_stride in bytes; each message only
  // when someone listens.
  void publish(const uint16_t* millimetres, int width, int height, size_t row_stride,
               const CameraIntrinsics& intrinsics, const std::string& frame_id, const ros::Time& stamp);

private:
  ros::Publisher image_pub_, info_pub_, cloud_pub_;
  std::vector<float> points_;
};

}  // namespace hough_plane_detector
