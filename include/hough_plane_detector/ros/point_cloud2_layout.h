// The layout of a sensor_msgs/PointCloud2 for the core's zero-copy CloudView.
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include "hough_plane_detector/core/cloud_view.h"

namespace hough_plane_detector
{

inline PointBufferLayout layoutOf(const sensor_msgs::PointCloud2& cloud)
{
  return layoutOfCloud(cloud);
}

}  // namespace hough_plane_detector
