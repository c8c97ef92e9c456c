// What a depth camera source publishes, with openni2_camera's names: depth/image_raw (16UC1,
// millimetres), depth/camera_info and the organized depth/points, one stamp and frame for all.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "hough_plane_detector/core/camera_intrinsics.h"

namespace hough_plane_detector
{

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
