// Offline plane detection over a rosbag or PCD files; one JSON object per frame.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/tools/cli_options.h"
#include "hough_plane_detector/tools/input_sources.h"

using namespace hough_plane_detector;

namespace
{
void usage(std::ostream& out)
{
  out << "usage: detect_planes --bag FILE --topic TOPIC [--world-frame odom] [options]\n"
         "       detect_planes FILE.pcd [FILE.pcd ...] [options]\n"
         "options:\n"
         "  --out FILE            write the JSON lines to FILE instead of stdout\n"
         "  --world-frame FRAME   frame the planes are reported in (bag input; default odom)\n"
         "  --camera-info TOPIC   camera_info of a depth-image topic (sensor_msgs/Image, 16UC1 mm or 32FC1 m;\n"
         "                        default: the camera_info beside the image topic)\n";
  for (const std::string& line : detectorParamHelp()) out << "  " << line << "\n";
}
}  // namespace

int main(int argc, char** argv)
{
  std::string bag_path, topic, world_frame = "odom", out_path, camera_info_topic;
  std::vector<std::string> pcd_paths;
  DetectorParams params;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help")
    {
      usage(std::cout);
      return 0;
    }
    if (arg.rfind("--", 0) == 0)
    {
      if (i + 1 >= argc)
      {
        std::cerr << "detect_planes: " << arg << " needs a value\n";
        return 2;
      }
      const std::string value = argv[++i];
      if (arg == "--bag") bag_path = value;
      else if (arg == "--topic") topic = value;
      else if (arg == "--world-frame") world_frame = value;
      else if (arg == "--camera-info") camera_info_topic = value;
      else if (arg == "--out") out_path = value;
      else
      {
        std::string error;
        std::string name = arg.substr(2);
        for (char& c : name)
          if (c == '-') c = '_';
        if (!setDetectorParam(params, name, value, &error))
        {
          std::cerr << "detect_planes: " << error << " (see --help)\n";
          return 2;
        }
      }
    }
    else
    {
      pcd_paths.push_back(arg);
    }
  }
  if (bag_path.empty() == pcd_paths.empty())
  {
    std::cerr << "detect_planes: give either --bag FILE --topic TOPIC or PCD files\n";
    usage(std::cerr);
    return 2;
  }
  if (!bag_path.empty() && topic.empty())
  {
    std::cerr << "detect_planes: --bag needs --topic\n";
    return 2;
  }
  std::string problem;
  if (!params.validate(&problem))
  {
    std::cerr << "detect_planes: invalid parameters: " << problem << "\n";
    return 2;
  }

  std::ofstream out_file;
  if (!out_path.empty())
  {
    out_file.open(out_path);
    if (!out_file)
    {
      std::cerr << "detect_planes: cannot write " << out_path << "\n";
      return 1;
    }
  }
  std::ostream& out = out_path.empty() ? std::cout : out_file;
  PlaneDetector detector(params);
  int frame_index = 0, processed = 0;

  auto run = [&](const PointBufferLayout& layout, const Eigen::Isometry3d& pose, double stamp,
                 const std::string& frame_id, const std::string& what) {
    CloudView view;
    std::vector<float> converted;
    std::string error;
    if (!makeCloudView(layout, view, converted, &error) || !detector.processFrame(view, pose, stamp, &error))
    {
      std::cerr << "detect_planes: " << what << ": " << error << "\n";
      ++frame_index;
      return false;
    }
    std::vector<std::vector<PlaneOutline>> outlines;
    for (const DetectedPlane& plane : detector.planes()) outlines.push_back(detector.outlines(plane));
    out << frameToJson(frame_index++, stamp, frame_id, detector.lastTimings().total_ms, detector.planes(), outlines)
        << "\n";
    ++processed;
    return true;
  };

  if (!pcd_paths.empty())
  {
    for (const std::string& path : pcd_paths)
    {
      pcl::PCLPointCloud2 cloud;
      std::string error;
      if (!loadPcd(path, cloud, &error))
      {
        std::cerr << "detect_planes: " << error << "\n";
        return 1;
      }
      // A still camera: the camera frame is the world frame.
      if (!run(layoutOf(cloud), Eigen::Isometry3d::Identity(), cloud.header.stamp * 1e-6,
               cloud.header.frame_id.empty() ? "camera" : cloud.header.frame_id, path))
        return 1;
    }
    return 0;
  }

  BagFrameSource source;
  std::string error;
  if (!source.open(bag_path, topic, world_frame, &error, camera_info_topic))
  {
    std::cerr << "detect_planes: " << error << "\n";
    return 1;
  }
  BagFrame frame;
  int skipped = 0;
  while (source.next(frame))
  {
    const double stamp = frame.cloud->header.stamp.toSec();
    if (!frame.usable)
    {
      std::cerr << "detect_planes: warning: frame " << frame_index << " skipped: " << frame.skip_reason << "\n";
      ++frame_index;
      ++skipped;
      continue;
    }
    if (!run(layoutOf(*frame.cloud), frame.camera_to_world, stamp, world_frame,
             "frame " + std::to_string(frame_index) + " of " + topic))
      ++skipped;
  }
  if (processed == 0)
  {
    std::cerr << "detect_planes: no frame of " << topic << " could be processed (" << skipped << " skipped)\n";
    return 1;
  }
  return 0;
}
