// make tsan-control links this instead of src/ros/map_lock.cpp: the map is never locked, so
// concurrency.test under ThreadSanitizer must report races (scripts/run_tsan.sh checks that
// some pass through saveMapService). Never part of a product build.
#include "hough_plane_detector/ros/plane_detector_ros.h"

namespace hough_plane_detector
{

std::unique_lock<std::mutex> PlaneDetectorRos::lockMap() { return std::unique_lock<std::mutex>(map_mutex_, std::defer_lock); }

}  // namespace hough_plane_detector
