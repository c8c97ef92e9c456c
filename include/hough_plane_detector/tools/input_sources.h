// Where the offline tools get frames: PCD files (a still camera) and rosbags (PointCloud2 plus
// /tf and /tf_static, transformed into a world frame).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <pcl/PCLPointCloud2.h>
#include <sensor_msgs/PointCloud2.h>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/ros/point_cloud2_layout.h"

namespace hough_plane_detector
{

PointBufferLayout layoutOf(const pcl::PCLPointCloud2& cloud);

// Loads a PCD file whose header passed checkPcdHeader; false with `error` naming the file and
// the problem.
bool loadPcd(const std::string& path, pcl::PCLPointCloud2& cloud, std::string* error);

struct BagFrame
{
  sensor_msgs::PointCloud2::ConstPtr cloud;
  Eigen::Isometry3d camera_to_world = Eigen::Isometry3d::Identity();
  bool has_transform = false;
  std::string transform_error;  // why has_transform is false
};

// Reads a bag in two passes: all transforms first (clouds often precede their tf in a bag),
// then the clouds in order, each with its camera -> world transform at its stamp.
class BagFrameSource
{
public:
  BagFrameSource();
  ~BagFrameSource();
  // False with `error` set when the bag cannot be read or the topic holds no PointCloud2.
  bool open(const std::string& path, const std::string& topic, const std::string& world_frame, std::string* error);
  bool next(BagFrame& frame);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hough_plane_detector
