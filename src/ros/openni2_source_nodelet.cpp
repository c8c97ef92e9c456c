// A Kinect path on Debian, where openni2_camera is not packaged: the first OpenNI2 depth device
// (or ~device_uri, also an .oni recording) as organized clouds on depth/points in
// camera_depth_optical_frame, openni2_camera's names.
#include <atomic>
#include <memory>
#include <thread>

#include <OpenNI.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "hough_plane_detector/core/depth_image.h"

namespace hough_plane_detector
{

class OpenNI2SourceNodelet : public nodelet::Nodelet
{
public:
  ~OpenNI2SourceNodelet() override
  {
    running_ = false;
    if (reader_.joinable()) reader_.join();
    if (stream_.isValid())
    {
      stream_.stop();
      stream_.destroy();
    }
    if (device_.isValid()) device_.close();
    if (initialized_) openni::OpenNI::shutdown();
  }

private:
  // OpenNI2's messages end in tabs and newlines; keep log lines on one line.
  static std::string openniError()
  {
    std::string e = openni::OpenNI::getExtendedError();
    for (char& c : e)
      if (c == '\n' || c == '\t') c = ' ';
    return e;
  }

  void onInit() override
  {
    ros::NodeHandle& private_nh = getPrivateNodeHandle();
    std::string uri;
    private_nh.param<std::string>("device_uri", uri, "");
    private_nh.param<std::string>("frame_id", frame_id_, "camera_depth_optical_frame");
    if (openni::OpenNI::initialize() != openni::STATUS_OK)
    {
      NODELET_FATAL("OpenNI2 did not start: %s", openniError().c_str());
      return;
    }
    initialized_ = true;
    if (device_.open(uri.empty() ? openni::ANY_DEVICE : uri.c_str()) != openni::STATUS_OK)
    {
      const std::string which = uri.empty() ? "found" : "'" + uri + "'";
      NODELET_FATAL("No OpenNI2 depth device %s: %s. Plug in a Kinect/Xtion (and check USB permissions), or give "
                    "~device_uri (an .oni recording works); no clouds will be published.",
                    which.c_str(), openniError().c_str());
      return;
    }
    if (stream_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK || stream_.start() != openni::STATUS_OK)
    {
      NODELET_FATAL("The OpenNI2 device has no usable depth stream: %s", openniError().c_str());
      return;
    }
    const openni::VideoMode mode = stream_.getVideoMode();
    intrinsics_ = intrinsicsFromFieldOfView(mode.getResolutionX(), mode.getResolutionY(),
                                            stream_.getHorizontalFieldOfView(), stream_.getVerticalFieldOfView());
    metres_per_unit_ = mode.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM ? 0.0001 : 0.001;
    cloud_pub_ = getNodeHandle().advertise<sensor_msgs::PointCloud2>("depth/points", 2);
    NODELET_INFO("OpenNI2 depth %d x %d at %d fps, fx %.1f, on %s.", mode.getResolutionX(), mode.getResolutionY(),
                 mode.getFps(), intrinsics_.fx, cloud_pub_.getTopic().c_str());
    running_ = true;
    reader_ = std::thread([this] { readLoop(); });
  }

  void readLoop()
  {
    openni::VideoStream* streams[1] = {&stream_};
    std::vector<float> points;
    while (running_ && ros::ok())
    {
      int ready = -1;
      if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, 500) != openni::STATUS_OK) continue;
      openni::VideoFrameRef frame;
      if (stream_.readFrame(&frame) != openni::STATUS_OK || !frame.isValid()) continue;
      if (cloud_pub_.getNumSubscribers() == 0) continue;
      depthImageToPoints(static_cast<const uint16_t*>(frame.getData()), frame.getWidth(), frame.getHeight(),
                         frame.getStrideInBytes(), intrinsics_, metres_per_unit_, points);
      sensor_msgs::PointCloud2::Ptr cloud(new sensor_msgs::PointCloud2);
      cloud->header.stamp = ros::Time::now();
      cloud->header.frame_id = frame_id_;
      sensor_msgs::PointCloud2Modifier modifier(*cloud);
      modifier.setPointCloud2FieldsByString(1, "xyz");
      modifier.resize(points.size() / 3);
      cloud->width = frame.getWidth();
      cloud->height = frame.getHeight();
      cloud->row_step = cloud->point_step * cloud->width;
      cloud->is_dense = false;
      sensor_msgs::PointCloud2Iterator<float> it(*cloud, "x");
      for (size_t i = 0; i < points.size(); i += 3, ++it)
      {
        it[0] = points[i];
        it[1] = points[i + 1];
        it[2] = points[i + 2];
      }
      cloud_pub_.publish(cloud);
    }
  }

  bool initialized_ = false;
  openni::Device device_;
  openni::VideoStream stream_;
  CameraIntrinsics intrinsics_;
  double metres_per_unit_ = 0.001;
  std::string frame_id_;
  ros::Publisher cloud_pub_;
  std::atomic<bool> running_{false};
  std::thread reader_;
};

}  // namespace hough_plane_detector

PLUGINLIB_EXPORT_CLASS(hough_plane_detector::OpenNI2SourceNodelet, nodelet::Nodelet)
