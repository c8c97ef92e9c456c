// A Kinect v1 through Debian's libfreenect (OpenNI2 in Debian has no Kinect driver): depth at
// VGA as depth/image_raw (16UC1 mm), depth/camera_info and the organized depth/points, with
// openni2_camera's names, stamped from the device's frame timestamps. Run under fakenect
// (LD_LIBRARY_PATH=<libdir>/fakenect FAKENECT_PATH=<dump>) it plays a recording instead.
#include <dlfcn.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <thread>
#include <vector>

#include <libfreenect.h>
#include <libfreenect_registration.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "hough_plane_detector/core/depth_image.h"
#include "hough_plane_detector/ros/depth_camera_publisher.h"

namespace hough_plane_detector
{

class FreenectSourceNodelet : public nodelet::Nodelet
{
public:
  ~FreenectSourceNodelet() override
  {
    running_ = false;
    if (reader_.joinable()) reader_.join();
    if (device_)
    {
      freenect_stop_depth(device_);
      freenect_close_device(device_);
    }
    if (context_) freenect_shutdown(context_);
  }

private:
  void onInit() override
  {
    ros::NodeHandle& private_nh = getPrivateNodeHandle();
    int device_index;
    private_nh.param("device_index", device_index, 0);
    private_nh.param<std::string>("frame_id", frame_id_, "camera_depth_optical_frame");
    private_nh.param("device_clock_hz", device_clock_hz_, 60.0e6);
    if (!(device_clock_hz_ > 0.0))
    {
      NODELET_ERROR("~device_clock_hz must be > 0, got %g; using 60e6.", device_clock_hz_);
      device_clock_hz_ = 60.0e6;
    }
    clock_ = DeviceClock(device_clock_hz_);
    publisher_.advertise(getNodeHandle());
    if (!fakenectRecordingReadable()) return;
    if (!openDevice(device_index)) return;
    // The projection: the device's own focal length (its registration data), unless ~fx.. give
    // a calibration.
    const std::string focal_from = deviceFocalLength();
    private_nh.param("fx", intrinsics_.fx, intrinsics_.fx);
    private_nh.param("fy", intrinsics_.fy, intrinsics_.fy);
    private_nh.param("cx", intrinsics_.cx, intrinsics_.cx);
    private_nh.param("cy", intrinsics_.cy, intrinsics_.cy);
    NODELET_INFO("Kinect v1 %d depth projection: fx %.1f fy %.1f cx %.1f cy %.1f px (%s).", device_index,
                 intrinsics_.fx, intrinsics_.fy, intrinsics_.cx, intrinsics_.cy,
                 private_nh.hasParam("fx") ? "~fx.. given" : focal_from.c_str());
    running_ = true;
    reader_ = std::thread([this] { readLoop(); });
    NODELET_INFO("Kinect v1 %d streaming depth (640 x 480, 11-bit disparity) on %s.", device_index,
                 getNodeHandle().resolveName("depth/points").c_str());
  }

  // fakenect ends the whole process when its recording is missing and hands on whatever a cut
  // frame file holds: both are refused here, before fakenect reads them.
  bool fakenectRecordingReadable()
  {
    const char* path = std::getenv("FAKENECT_PATH");
    if (!path) return true;
    std::ifstream index(std::string(path) + "/INDEX.txt");
    if (!index.good())
    {
      NODELET_ERROR("FAKENECT_PATH=%s has no readable INDEX.txt (a fakenect-record dump): no depth will be published.",
                    path);
      return false;
    }
    std::string name;
    for (int line = 1; std::getline(index, name); ++line)
    {
      if (name.compare(0, 2, "d-") != 0) continue;  // depth frames; r- (colour) and a- (accelerometer) are not read
      const std::string problem = checkDepthFrameFile(std::string(path) + "/" + name);
      if (problem.empty()) continue;
      NODELET_ERROR("FAKENECT_PATH=%s: %s (INDEX.txt line %d); the recording ends mid-frame or is damaged, so no "
                    "depth will be published (cut INDEX.txt before that line to play the frames before it).",
                    path, problem.c_str(), line);
      return false;
    }
    return true;
  }

  // Empty when `file` is a whole fakenect depth frame: a "P5 <w> <h> <max>" header and w x h
  // 16-bit samples.
  static std::string checkDepthFrameFile(const std::string& file)
  {
    std::ifstream in(file, std::ios::binary | std::ios::ate);
    if (!in.good()) return file + " cannot be read";
    const std::streamoff size = in.tellg();
    in.seekg(0);
    std::string magic;
    long width = 0, height = 0, max_value = 0;
    if (!(in >> magic >> width >> height >> max_value) || magic != "P5" || width <= 0 || height <= 0 || max_value <= 255)
      return file + " has no 16-bit PGM header (P5 <width> <height> <max>)";
    in.get();  // the one whitespace after the header
    const std::streamoff expected = in.tellg() + std::streamoff(width) * height * 2;
    if (size < expected)
      return file + " holds " + std::to_string(size) + " of its " + std::to_string(expected) + " bytes";
    return std::string();
  }

  bool openDevice(int device_index)
  {
    if (freenect_init(&context_, nullptr) < 0)
    {
      NODELET_ERROR("libfreenect could not start (USB access?): no depth will be published.");
      context_ = nullptr;
      return false;
    }
    freenect_select_subdevices(context_, FREENECT_DEVICE_CAMERA);
    const int devices = freenect_num_devices(context_);
    if (device_index < 0 || device_index >= devices || freenect_open_device(context_, &device_, device_index) < 0)
    {
      NODELET_ERROR("No Kinect v1 number %d (%d found; is it plugged in, and may this user open it?): no depth "
                    "will be published.", device_index, devices);
      device_ = nullptr;
      return false;
    }
    const freenect_frame_mode mode = freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT);
    if (!mode.is_valid || freenect_set_depth_mode(device_, mode) < 0)
    {
      NODELET_ERROR("The Kinect refused 640 x 480 11-bit depth: no depth will be published.");
      return false;
    }
    width_ = mode.width;
    height_ = mode.height;
    freenect_set_user(device_, this);
    freenect_set_depth_callback(device_, [](freenect_device* device, void* depth, uint32_t timestamp) {
      static_cast<FreenectSourceNodelet*>(freenect_get_user(device))->onDepth(static_cast<const uint8_t*>(depth), timestamp);
    });
    if (freenect_start_depth(device_) < 0)
    {
      NODELET_ERROR("The Kinect's depth stream did not start: no depth will be published.");
      return false;
    }
    return true;
  }

  // Sets fx = fy from the device's zero-plane data, as libfreenect's own freenect_camera_to_world
  // does (a pixel of reference_pixel_size mm at SXGA, so twice that at VGA, seen reference_distance
  // mm away); says where the focal length came from. Looked up at run time in the libfreenect
  // actually loaded: fakenect's has no registration, and a direct call would keep the nodelet from
  // loading there (RTLD_DEFAULT would not see a library the nodelet manager loaded locally).
  std::string deviceFocalLength()
  {
    using CopyRegistration = freenect_registration (*)(freenect_device*);
    using DestroyRegistration = int (*)(freenect_registration*);
    Dl_info library;
    void* handle = nullptr;
    if (dladdr(reinterpret_cast<void*>(&freenect_init), &library) && library.dli_fname)
      handle = dlopen(library.dli_fname, RTLD_LAZY | RTLD_NOLOAD);
    if (!handle) return "nominal: the loaded libfreenect could not be inspected";
    const auto copy = reinterpret_cast<CopyRegistration>(dlsym(handle, "freenect_copy_registration"));
    const auto destroy = reinterpret_cast<DestroyRegistration>(dlsym(handle, "freenect_destroy_registration"));
    if (!copy || !destroy)
    {
      dlclose(handle);
      return "nominal: this libfreenect (fakenect?) has no registration data";
    }
    freenect_registration registration = copy(device_);
    const double distance = registration.zero_plane_info.reference_distance;
    const double pixel = registration.zero_plane_info.reference_pixel_size;
    destroy(&registration);
    dlclose(handle);
    const double focal = distance / (2.0 * pixel);
    if (!(distance > 0.0 && pixel > 0.0 && focal > 100.0 && focal < 2000.0))
      return "nominal: the device's registration data gave no usable focal length";
    intrinsics_.fx = intrinsics_.fy = focal;
    return "the device's registration data";
  }

  void readLoop()
  {
    timeval timeout{0, 100000};
    while (running_ && ros::ok())
      if (freenect_process_events_timeout(context_, &timeout) < 0)
      {
        NODELET_INFO("The Kinect's depth stream ended (the end of a fakenect recording, or the device is gone).");
        break;
      }
  }

  // `raw`: 16-bit disparities, not necessarily 2-byte aligned (fakenect hands on its file buffer
  // just past the PGM header), so each is copied out, never dereferenced as uint16_t.
  void onDepth(const uint8_t* raw, uint32_t ticks)
  {
    // The 32-bit frame counter wraps: unwrapped here, so the clock sees it grow.
    if (have_ticks_ && ticks < last_ticks_) wraps_ += uint64_t(1) << 32;
    have_ticks_ = true;
    last_ticks_ = ticks;
    const ros::Time stamp = clock_.stamp(wraps_ + ticks, ros::Time::now());
    millimetres_.resize(static_cast<size_t>(width_) * height_);
    for (size_t i = 0; i < millimetres_.size(); ++i)
    {
      uint16_t disparity;
      std::memcpy(&disparity, raw + 2 * i, sizeof(disparity));
      millimetres_[i] = kinectDisparityToMillimetres(disparity, intrinsics_);
    }
    publisher_.publish(millimetres_.data(), width_, height_, width_ * sizeof(uint16_t), intrinsics_, frame_id_, stamp);
  }

  freenect_context* context_ = nullptr;
  freenect_device* device_ = nullptr;
  int width_ = 640, height_ = 480;
  CameraIntrinsics intrinsics_;
  std::string frame_id_;
  double device_clock_hz_ = 60.0e6;
  DeviceClock clock_{60.0e6};
  bool have_ticks_ = false;
  uint32_t last_ticks_ = 0;
  uint64_t wraps_ = 0;
  std::vector<uint16_t> millimetres_;
  DepthCameraPublisher publisher_;
  std::atomic<bool> running_{false};
  std::thread reader_;
};

}  // namespace hough_plane_detector

PLUGINLIB_EXPORT_CLASS(hough_plane_detector::FreenectSourceNodelet, nodelet::Nodelet)
