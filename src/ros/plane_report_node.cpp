// Watches the detector for a while, then prints its planes next to the simulated scene's true
// planes and writes the last segmented frame as a PNG (each plane in its marker colour).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "hough_plane_detector/tools/png_image.h"

using namespace hough_plane_detector;

namespace
{
// The map beside the scene's true planes.
void printMap(const PlaneArray& planes, int arrays, const std::vector<TruePlane>& truth)
{
  std::printf("\n%d plane arrays received; the map now (%s frame, n.p + d = 0):\n", arrays, planes.header.frame_id.c_str());
  std::printf("  id  normal                      d        strength  support  hull  | true plane        E_angle  E_d\n");
  for (const Plane& p : planes.planes)
  {
    const Eigen::Vector3d n(p.normal.x, p.normal.y, p.normal.z);
    const TruePlane* best = nearestTruePlane(n, p.d, truth);
    std::printf("  %2d  (%+.3f %+.3f %+.3f)  %+7.3f  %8.2f  %7u  %4zu  | ", p.id, n.x(), n.y(), n.z(), p.d, p.strength,
                p.support, p.hull.points.size());
    if (best)
      std::printf("%-16s  %.4f   %.4f\n", best->name.c_str(), angleError(n, best->normal),
                  distanceError(n, p.d, best->normal, best->d));
    else
      std::printf("(no true plane)\n");
  }
}

// The segmented cloud as a PNG: each pixel in its plane's colour (grey when on none), shaded by
// depth so the room's shape shows; black where there was no return.
bool writeSegmentedPng(const sensor_msgs::PointCloud2& segmented, const std::string& path, std::string* error)
{
  std::vector<uint8_t> image(static_cast<size_t>(segmented.width) * segmented.height * 3, 0);
  sensor_msgs::PointCloud2ConstIterator<float> z(segmented, "z");
  sensor_msgs::PointCloud2ConstIterator<uint8_t> rgb(segmented, "rgb");
  for (size_t i = 0; i < image.size() / 3; ++i, ++z, ++rgb)
  {
    if (!std::isfinite(*z)) continue;
    const double shade = std::max(0.35, 1.0 - 0.1 * *z);
    image[3 * i] = static_cast<uint8_t>(rgb[2] * shade);  // PointCloud2 packs rgb as b, g, r bytes
    image[3 * i + 1] = static_cast<uint8_t>(rgb[1] * shade);
    image[3 * i + 2] = static_cast<uint8_t>(rgb[0] * shade);
  }
  return writePng(path, segmented.width, segmented.height, image, error);
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "plane_report");
  ros::NodeHandle nh, private_nh("~");
  double duration;
  std::string scene_name, picture, detector;
  private_nh.param("duration", duration, 20.0);
  private_nh.param<std::string>("scene", scene_name, "office");
  private_nh.param<std::string>("picture", picture, "/tmp/hough_plane_detector_demo.png");
  private_nh.param<std::string>("detector", detector, "/hough_plane_detector");

  std::mutex mutex;
  PlaneArray::ConstPtr planes;
  sensor_msgs::PointCloud2::ConstPtr segmented;
  int arrays = 0;
  ros::Subscriber planes_sub = nh.subscribe<PlaneArray>(detector + "/planes", 2, [&](const PlaneArray::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    planes = m;
    ++arrays;
  });
  ros::Subscriber cloud_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      detector + "/segmented_cloud", 1, [&](const sensor_msgs::PointCloud2::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        segmented = m;
      });
  ROS_INFO("Watching %s for %.0f s.", detector.c_str(), duration);
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(duration);
  while (ros::ok() && ros::WallTime::now() < end)
  {
    ros::spinOnce();
    ros::WallDuration(0.05).sleep();
  }
  std::lock_guard<std::mutex> lock(mutex);
  if (!planes)
  {
    std::fprintf(stderr, "plane_report: no plane array received from %s\n", detector.c_str());
    return 1;
  }
  printMap(*planes, arrays, (scene_name == "hall" ? makeRampStairsHall() : makeOfficeRoom()).truePlanes());
  if (!segmented)
  {
    std::fprintf(stderr, "plane_report: no segmented cloud received\n");
    return 1;
  }
  std::string error;
  if (!writeSegmentedPng(*segmented, picture, &error))
  {
    std::fprintf(stderr, "plane_report: %s\n", error.c_str());
    return 1;
  }
  std::printf("\nPicture of the last frame, each pixel in its plane's colour: %s\n", picture.c_str());
  return 0;
}
