#include "hough_plane_detector/ros/plane_detector_ros.h"

namespace hough_plane_detector
{

std::unique_lock<std::mutex> PlaneDetectorRos::lockMap() { return std::unique_lock<std::mutex>(map_mutex_); }

}  // namespace hough_plane_detector
