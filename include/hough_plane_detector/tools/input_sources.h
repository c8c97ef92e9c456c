// Where the offline tools get frames: PCD files (a still camera) and rosbags (PointCloud2 plus
// /tf and /tf_static, transformed into a world frame).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <pcl/PCLPointCloud2.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/ros/point_cloud2_layout.h"

namespace hough_plane_detector
{

PointBufferLayout layoutOf(const pcl::PCLPointCloud2& cloud);

// Loads a PCD file whose header passed checkPcdHeader; false with `error` naming the file and
// the problem.
bool loadPcd(const std::string& path, pcl::PCLPointCloud2& cloud, std::string* error);

// An organized x y z cloud (float32, NaN where no return) from a depth image (16UC1 or mono16
// in millimetres, 32FC1 in metres) and its camera_info; false with `error` naming what is wrong
// (an encoding of no depth, a camera_info of zeros, sizes that disagree, a short buffer).
bool depthImageToCloud(const sensor_msgs::Image& image, const sensor_msgs::CameraInfo& info,
                       sensor_msgs::PointCloud2& cloud, std::string* error);

struct BagFrame
{
  sensor_msgs::PointCloud2::ConstPtr cloud;
  Eigen::Isometry3d camera_to_world = Eigen::Isometry3d::Identity();
  bool usable = false;      // a cloud with its transform
  std::string skip_reason;  // why not: no transform, a depth image that cannot become a cloud
};

// Reads a bag in two passes: all transforms first (clouds often precede their tf in a bag),
// then the clouds (or depth images, made clouds with the latest camera_info) in order, each
// with its camera -> world transform at its stamp. Frame ids with a leading '/' (tf1-era bags)
// are read without it.
class BagFrameSource
{
public:
  BagFrameSource();
  ~BagFrameSource();
  // False with `error` set when the bag cannot be read or the topic holds neither PointCloud2
  // nor Image (an Image topic needs its CameraInfo: `camera_info_topic`, by default the
  // topic beside the image's, .../camera_info).
  bool open(const std::string& path, const std::string& topic, const std::string& world_frame, std::string* error,
            const std::string& camera_info_topic = "");
  bool next(BagFrame& frame);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hough_plane_detector
