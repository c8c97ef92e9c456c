// An Xtion / PrimeSense path on Debian, where openni2_camera is not packaged: the first OpenNI2
// depth device (or ~device_uri, also an .oni recording) at 640 x 480 millimetres as
// depth/image_raw, depth/camera_info and the organized depth/points in
// camera_depth_optical_frame (openni2_camera's names), stamped from the device's clock.
#include <atomic>
#include <memory>
#include <thread>

#include <OpenNI.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "hough_plane_detector/core/depth_image.h"
#include "hough_plane_detector/ros/depth_camera_publisher.h"

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
    if (stream_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK)
    {
      NODELET_FATAL("The OpenNI2 device has no usable depth stream: %s", openniError().c_str());
      return;
    }
    selectVgaMillimetres();
    if (stream_.start() != openni::STATUS_OK)
    {
      NODELET_FATAL("The OpenNI2 depth stream did not start: %s", openniError().c_str());
      return;
    }
    const openni::VideoMode mode = stream_.getVideoMode();
    intrinsics_ = intrinsicsFromFieldOfView(mode.getResolutionX(), mode.getResolutionY(),
                                            stream_.getHorizontalFieldOfView(), stream_.getVerticalFieldOfView());
    tenths_of_millimetres_ = mode.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM;
    publisher_.advertise(getNodeHandle());
    NODELET_INFO("OpenNI2 depth %d x %d at %d fps, fx %.1f, on %s.", mode.getResolutionX(), mode.getResolutionY(),
                 mode.getFps(), intrinsics_.fx, getNodeHandle().resolveName("depth/points").c_str());
    running_ = true;
    reader_ = std::thread([this] { readLoop(); });
  }

  // An Xtion starts in QVGA: ask for 640 x 480 millimetres at the highest rate up to 30 fps.
  void selectVgaMillimetres()
  {
    const openni::SensorInfo& info = stream_.getSensorInfo();
    const openni::Array<openni::VideoMode>& modes = info.getSupportedVideoModes();
    int best = -1;
    for (int i = 0; i < modes.getSize(); ++i)
    {
      const openni::VideoMode& m = modes[i];
      if (m.getResolutionX() != 640 || m.getResolutionY() != 480 || m.getPixelFormat() != openni::PIXEL_FORMAT_DEPTH_1_MM ||
          m.getFps() > 30)
        continue;
      if (best < 0 || m.getFps() > modes[best].getFps()) best = i;
    }
    if (best < 0 || stream_.setVideoMode(modes[best]) != openni::STATUS_OK)
      NODELET_WARN("The OpenNI2 device offers no 640 x 480 millimetre depth mode: using its default.");
  }

  void readLoop()
  {
    openni::VideoStream* streams[1] = {&stream_};
    std::vector<uint16_t> millimetres;
    while (running_ && ros::ok())
    {
      int ready = -1;
      if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, 500) != openni::STATUS_OK) continue;
      openni::VideoFrameRef frame;
      if (stream_.readFrame(&frame) != openni::STATUS_OK || !frame.isValid()) continue;
      const ros::Time stamp = clock_.stamp(frame.getTimestamp(), ros::Time::now());  // microseconds
      const uint16_t* depth = static_cast<const uint16_t*>(frame.getData());
      size_t stride = frame.getStrideInBytes();
      if (tenths_of_millimetres_)
      {
        millimetres.resize(static_cast<size_t>(frame.getWidth()) * frame.getHeight());
        for (int v = 0; v < frame.getHeight(); ++v)
          for (int u = 0; u < frame.getWidth(); ++u)
            millimetres[static_cast<size_t>(v) * frame.getWidth() + u] =
                reinterpret_cast<const uint16_t*>(reinterpret_cast<const uint8_t*>(depth) + v * stride)[u] / 10;
        depth = millimetres.data();
        stride = frame.getWidth() * sizeof(uint16_t);
      }
      publisher_.publish(depth, frame.getWidth(), frame.getHeight(), stride, intrinsics_, frame_id_, stamp);
    }
  }

  bool initialized_ = false;
  openni::Device device_;
  openni::VideoStream stream_;
  CameraIntrinsics intrinsics_;
  bool tenths_of_millimetres_ = false;  // PIXEL_FORMAT_DEPTH_100_UM
  std::string frame_id_;
  DeviceClock clock_{1.0e6};  // OpenNI2 frame timestamps are microseconds
  DepthCameraPublisher publisher_;
  std::atomic<bool> running_{false};
  std::thread reader_;
};

}  // namespace hough_plane_detector

PLUGINLIB_EXPORT_CLASS(hough_plane_detector::OpenNI2SourceNodelet, nodelet::Nodelet)
