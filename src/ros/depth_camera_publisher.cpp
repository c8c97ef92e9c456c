#include "hough_plane_detector/ros/depth_camera_publisher.h"

#include <cmath>
#include <cstring>

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "hough_plane_detector/core/depth_image.h"

namespace hough_plane_detector
{

ros::Time DeviceClock::stamp(uint64_t ticks, const ros::Time& now)
{
  if (anchored_ && ticks >= anchor_ticks_)
  {
    const ros::Time stamp = anchor_time_ + ros::Duration((ticks - anchor_ticks_) / ticks_per_second_);
    if (std::abs((stamp - now).toSec()) < 0.1) return stamp;
  }
  anchored_ = true;
  anchor_ticks_ = ticks;
  anchor_time_ = now;
  return now;
}

void DepthCameraPublisher::advertise(ros::NodeHandle& nh)
{
  image_pub_ = nh.advertise<sensor_msgs::Image>("depth/image_raw", 2);
  info_pub_ = nh.advertise<sensor_msgs::CameraInfo>("depth/camera_info", 2);
  cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("depth/points", 2);
}

void DepthCameraPublisher::publish(const uint16_t* millimetres, int width, int height, size_t row_stride,
                                   const CameraIntrinsics& k, const std::string& frame_id, const ros::Time& stamp)
{
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame_id;
  if (image_pub_.getNumSubscribers() > 0)
  {
    sensor_msgs::Image::Ptr image(new sensor_msgs::Image);
    image->header = header;
    image->width = width;
    image->height = height;
    image->encoding = sensor_msgs::image_encodings::TYPE_16UC1;
    image->step = width * sizeof(uint16_t);
    image->data.resize(static_cast<size_t>(image->step) * height);
    for (int v = 0; v < height; ++v)
      std::memcpy(&image->data[static_cast<size_t>(v) * image->step],
                  reinterpret_cast<const uint8_t*>(millimetres) + v * row_stride, image->step);
    image_pub_.publish(image);
  }
  if (info_pub_.getNumSubscribers() > 0)
  {
    sensor_msgs::CameraInfo::Ptr info(new sensor_msgs::CameraInfo(cameraInfoOf(k, header)));
    info->width = width;  // the frame's, should a device send another size than it announced
    info->height = height;
    info_pub_.publish(info);
  }
  if (cloud_pub_.getNumSubscribers() == 0) return;
  depthImageToPoints(millimetres, width, height, row_stride, k, 0.001, points_);
  sensor_msgs::PointCloud2::Ptr cloud(new sensor_msgs::PointCloud2);
  cloud->header = header;
  sensor_msgs::PointCloud2Modifier modifier(*cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(points_.size() / 3);
  cloud->width = width;
  cloud->height = height;
  cloud->row_step = cloud->point_step * cloud->width;
  cloud->is_dense = false;
  sensor_msgs::PointCloud2Iterator<float> it(*cloud, "x");
  for (size_t i = 0; i < points_.size(); i += 3, ++it)
  {
    it[0] = points_[i];
    it[1] = points_[i + 1];
    it[2] = points_[i + 2];
  }
  cloud_pub_.publish(cloud);
}

}  // namespace hough_plane_detector
