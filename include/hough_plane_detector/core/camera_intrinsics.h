// Pinhole intrinsics and range of a depth camera (a Kinect's by default): the depth-image
// conversion of the camera sources and the scene renderer share them.
#pragma once

namespace hough_plane_detector
{

struct CameraIntrinsics
{
  int width = 640;
  int height = 480;
  double fx = 580.0;
  double fy = 580.0;
  double cx = 319.5;
  double cy = 239.5;
  double min_range = 0.5;  // Kinect returns nothing nearer or farther
  double max_range = 6.0;
};

}  // namespace hough_plane_detector
