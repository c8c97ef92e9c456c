// The layout of a sensor_msgs/PointCloud2 for the core's zero-copy CloudView.
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include "hough_plane_detector/core/cloud_view.h"

namespace hough_plane_detector
{

inline PointBufferLayout layoutOf(const sensor_msgs::PointCloud2& cloud)
{
  PointBufferLayout layout;
  layout.width = cloud.width;
  layout.height = cloud.height;
  layout.point_step = cloud.point_step;
  layout.row_step = cloud.row_step;
  layout.is_bigendian = cloud.is_bigendian;
  for (const auto& f : cloud.fields) layout.fields.push_back(PointFieldLayout{f.name, f.offset, f.datatype, f.count});
  layout.data = cloud.data.data();
  layout.data_size = cloud.data.size();
  return layout;
}

}  // namespace hough_plane_detector
