// The Kinect v1 source without a Kinect: a rendered room written in fakenect's dump format
// (INDEX.txt, one "P5 640 480 65535" file of little-endian 11-bit disparities per frame) and
// played by Debian's fakenect library through FreenectSourceNodelet into the detector.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/core/depth_image.h"
#include "plane_array_helpers.h"
#include "test_bags.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

namespace
{
constexpr char kFakenectLibraries[] = "/usr/lib/x86_64-linux-gnu/fakenect";
constexpr int kFrames = 60;  // 2 s at 30 Hz

// Writes the still camera's frames; returns the room's planes with 20,000+ points in view, in
// the camera frame.
std::vector<TruePlane> writeFakenectDump(const std::string& dir)
{
  mkdir(dir.c_str(), 0755);
  SceneRenderer renderer(makeOfficeRoom());
  const Eigen::Isometry3d pose = roomTour(8)[2];
  KinectNoise exact;
  exact.gaussian = false;  // the raw disparity's own steps are the sensor's quantization
  exact.quantize = false;
  const RenderedFrame frame = renderer.render(pose, exact, 1);
  std::vector<uint16_t> raw(static_cast<size_t>(frame.width) * frame.height);
  for (size_t i = 0; i < raw.size(); ++i) raw[i] = kinectMetresToDisparity(frame.xyz[3 * i + 2]);
  std::ofstream index(dir + "/INDEX.txt");
  for (int f = 0; f < kFrames; ++f)
  {
    char name[64];
    std::snprintf(name, sizeof(name), "d-%.6f-%u.pgm", 1000.0 + f / 30.0, 1000000u + 2000000u * f);  // 60 MHz ticks
    std::ofstream pgm(dir + "/" + name, std::ios::binary);
    pgm << "P5 640 480 65535\n";
    pgm.write(reinterpret_cast<const char*>(raw.data()), raw.size() * sizeof(uint16_t));
    index << name << "\n";
  }
  std::vector<TruePlane> in_view;
  for (size_t t = 0; t < renderer.truePlanes().size(); ++t)
    if (frame.visible_points[t] >= 20000)
    {
      TruePlane p = renderer.truePlanes()[t];
      const Eigen::Vector3d n = pose.linear().transpose() * p.normal;
      p.d = p.d + p.normal.dot(pose.translation());
      p.normal = n;
      in_view.push_back(p);
    }
  return in_view;
}

// Runs the source as a standalone nodelet under fakenect for `seconds`; its output.
std::string playThroughFreenectSource(const std::string& dump, double seconds)
{
  int code = 0;
  return runCommand("timeout -s INT " + std::to_string(seconds) + " env FAKENECT_PATH=" + dump +
                        " LD_LIBRARY_PATH=" + kFakenectLibraries + ":${LD_LIBRARY_PATH}" +
                        " rosrun nodelet nodelet standalone hough_plane_detector/FreenectSourceNodelet"
                        " __name:=freenect_source __ns:=/camera",
                    &code);
}
}  // namespace

TEST(FreenectSource, AFakenectRecordingOfARoomGivesItsPlanes)
{
  const std::string dump = "/tmp/hough_plane_detector_fakenect";
  const std::vector<TruePlane> truth = writeFakenectDump(dump);
  ASSERT_GE(truth.size(), 2u);

  std::mutex mutex;
  PlaneArray::ConstPtr planes;
  sensor_msgs::Image::ConstPtr image;
  sensor_msgs::CameraInfo::ConstPtr info;
  ros::NodeHandle nh;
  ros::WallTime last_planes;
  ros::Subscriber planes_sub = nh.subscribe<PlaneArray>("/hough_plane_detector/planes", 10, [&](const PlaneArray::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    planes = m;
    last_planes = ros::WallTime::now();
  });
  ros::Subscriber image_sub = nh.subscribe<sensor_msgs::Image>("/camera/depth/image_raw", 10, [&](const sensor_msgs::Image::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    image = m;
  });
  ros::Subscriber info_sub = nh.subscribe<sensor_msgs::CameraInfo>("/camera/depth/camera_info", 10,
                                                                   [&](const sensor_msgs::CameraInfo::ConstPtr& m) {
                                                                     std::lock_guard<std::mutex> lock(mutex);
                                                                     info = m;
                                                                   });
  const std::string output = playThroughFreenectSource(dump, 10.0);
  EXPECT_NE(output.find("streaming depth"), std::string::npos) << output;
  EXPECT_NE(output.find("depth stream ended"), std::string::npos) << output;
  // fakenect has no registration data: the nominal projection, and the log says so.
  EXPECT_NE(output.find("fx 580.0 fy 580.0 cx 319.5 cy 239.5 px (nominal: this libfreenect (fakenect?) has no "
                        "registration data)"),
            std::string::npos)
      << output;
  // The last frames' plane arrays: until all three topics were heard and the planes have been
  // quiet for half a second (the source has ended), 10 s at most.
  waitUntil(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return image && info && planes && ros::WallTime::now() - last_planes > ros::WallDuration(0.5);
      },
      10.0);

  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_TRUE(image) << "no depth/image_raw\n" << output;
  EXPECT_EQ(image->encoding, "16UC1");
  EXPECT_EQ(image->width, 640u);
  EXPECT_EQ(image->height, 480u);
  EXPECT_EQ(image->header.frame_id, "camera_depth_optical_frame");
  ASSERT_TRUE(info) << "no depth/camera_info";
  EXPECT_DOUBLE_EQ(info->K[0], 580.0);
  ASSERT_TRUE(planes) << "no plane array: the fakenect frames never reached the detector\n" << output;
  // Every large plane in view once, within 0.01 rad and 2 cm, from the raw disparity's steps.
  for (const TruePlane& t : truth)
    EXPECT_EQ(matchesOf(*planes, t, 0.01, 0.02), 1) << t.name << " (n " << t.normal.transpose() << ", d " << t.d
                                                    << ") among " << planes->planes.size() << " planes";
}

TEST(FreenectSource, AMissingRecordingIsAClearErrorNotACrash)
{
  // fakenect itself ends the process when FAKENECT_PATH has no INDEX.txt; the source refuses first.
  const std::string output = playThroughFreenectSource("/tmp/hough_plane_detector_no_such_dump", 3.0);
  EXPECT_NE(output.find("has no readable INDEX.txt"), std::string::npos) << output;
  EXPECT_EQ(output.find("Cannot open file"), std::string::npos) << "fakenect was reached: " << output;
}

TEST(FreenectSource, ARecordingThatEndsMidFrameIsAClearErrorNotAFrame)
{
  // A dump whose last depth file was cut (the recorder killed while writing) is refused with the
  // file named; fakenect would hand on whatever the cut file holds.
  const std::string whole = "/tmp/hough_plane_detector_fakenect", cut = "/tmp/hough_plane_detector_fakenect_cut";
  writeFakenectDump(whole);
  mkdir(cut.c_str(), 0755);
  std::ifstream index(whole + "/INDEX.txt");
  std::ofstream cut_index(cut + "/INDEX.txt");
  std::string name, last;
  for (int f = 0; f < 3 && std::getline(index, name); ++f)
  {
    std::ifstream from(whole + "/" + name, std::ios::binary);
    std::ofstream(cut + "/" + name, std::ios::binary) << from.rdbuf();
    cut_index << name << "\n";
    last = name;
  }
  cut_index.close();
  ASSERT_EQ(truncate((cut + "/" + last).c_str(), 300000), 0);
  const std::string output = playThroughFreenectSource(cut, 3.0);
  EXPECT_NE(output.find(last + " holds 300000 of its 614417 bytes"), std::string::npos) << output;
  EXPECT_NE(output.find("INDEX.txt line 3"), std::string::npos) << output;
  EXPECT_EQ(output.find("streaming depth"), std::string::npos) << "fakenect was reached: " << output;
}

int main(int argc, char** argv)
{
  return runRosTests(argc, argv, "test_freenect_source");
}
