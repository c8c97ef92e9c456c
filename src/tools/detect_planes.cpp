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
namespace po = boost::program_options;

namespace
{
// Detects in each frame given and writes its JSON line; counts frames.
class FrameWriter
{
public:
  FrameWriter(const DetectorParams& params, std::ostream& out) : detector_(params), out_(out) {}

  // False (message on stderr, the frame counted) when the cloud cannot be viewed or detected in.
  bool process(const PointBufferLayout& layout, const Eigen::Isometry3d& pose, double stamp, const std::string& frame_id,
               const std::string& what)
  {
    CloudView view;
    std::vector<float> converted;
    std::string error;
    if (!makeCloudView(layout, view, converted, &error) || !detector_.processFrame(view, pose, stamp, &error))
    {
      std::cerr << "detect_planes: " << what << ": " << error << "\n";
      ++frame_index_;
      return false;
    }
    std::vector<std::vector<PlaneOutline>> outlines;
    for (const DetectedPlane& plane : detector_.planes()) outlines.push_back(detector_.outlines(plane));
    out_ << frameToJson(frame_index_++, stamp, frame_id, detector_.lastTimings().total_ms, detector_.planes(), outlines)
         << "\n";
    ++processed_;
    return true;
  }
  void skip() { ++frame_index_; }
  int frameIndex() const { return frame_index_; }
  int processed() const { return processed_; }

private:
  PlaneDetector detector_;
  std::ostream& out_;
  int frame_index_ = 0, processed_ = 0;
};

// PCD files: each one frame of a still camera (the camera frame is the world frame).
int detectInPcds(const std::vector<std::string>& paths, FrameWriter& writer)
{
  for (const std::string& path : paths)
  {
    pcl::PCLPointCloud2 cloud;
    std::string error;
    if (!loadPcd(path, cloud, &error))
    {
      std::cerr << "detect_planes: " << error << "\n";
      return 1;
    }
    if (!writer.process(layoutOf(cloud), Eigen::Isometry3d::Identity(), cloud.header.stamp * 1e-6,
                        cloud.header.frame_id.empty() ? "camera" : cloud.header.frame_id, path))
      return 1;
  }
  return 0;
}

// A bag's clouds or depth images in world_frame; frames without a transform are skipped.
int detectInBag(const std::string& bag_path, const std::string& topic, const std::string& world_frame,
                const std::string& camera_info_topic, FrameWriter& writer)
{
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
      std::cerr << "detect_planes: warning: frame " << writer.frameIndex() << " skipped: " << frame.skip_reason << "\n";
      writer.skip();
      ++skipped;
      continue;
    }
    if (!writer.process(layoutOf(*frame.cloud), frame.camera_to_world, stamp, world_frame,
                        "frame " + std::to_string(writer.frameIndex()) + " of " + topic))
      ++skipped;
  }
  if (writer.processed() == 0)
  {
    std::cerr << "detect_planes: no frame of " << topic << " could be processed (" << skipped << " skipped)\n";
    return 1;
  }
  return 0;
}
}  // namespace

int main(int argc, char** argv)
{
  std::string bag_path, topic, world_frame, out_path, camera_info_topic;
  std::vector<std::string> pcd_paths;
  DetectorParams params;
  po::options_description tool("options"), detector_options("detector parameters (dashes for underscores work too)"),
      hidden;
  tool.add_options()("help,h", "this help")
      ("bag", po::value(&bag_path)->value_name("FILE"), "rosbag to read clouds or depth images from")
      ("topic", po::value(&topic)->value_name("TOPIC"), "sensor_msgs/PointCloud2 or sensor_msgs/Image topic of --bag")
      ("world-frame", po::value(&world_frame)->value_name("FRAME")->default_value("odom"),
       "frame the planes are reported in (bag input)")
      ("camera-info", po::value(&camera_info_topic)->value_name("TOPIC"),
       "camera_info of a depth-image topic (16UC1 mm or 32FC1 m; default: the camera_info beside the image topic)")
      ("out", po::value(&out_path)->value_name("FILE"), "write the JSON lines to FILE instead of stdout");
  addDetectorParamOptions(params, detector_options, hidden);
  hidden.add_options()("pcd", po::value(&pcd_paths));
  po::positional_options_description positional;
  positional.add("pcd", -1);
  po::options_description all;
  all.add(tool).add(detector_options).add(hidden);
  po::variables_map values;
  std::string parse_error;
  const char* usage = "usage: detect_planes --bag FILE --topic TOPIC [--world-frame odom] [options]\n"
                      "       detect_planes FILE.pcd [FILE.pcd ...] [options]\n";
  if (!parseCommandLine(argc, argv, all, positional, values, &parse_error))
  {
    std::cerr << "detect_planes: " << parse_error << " (see --help)\n";
    return 2;
  }
  if (values.count("help"))
  {
    std::cout << usage << tool << detector_options;
    return 0;
  }
  if (bag_path.empty() == pcd_paths.empty())
  {
    std::cerr << "detect_planes: give either --bag FILE --topic TOPIC or PCD files\n" << usage;
    return 2;
  }
  if (!bag_path.empty() && topic.empty())
  {
    std::cerr << "detect_planes: --bag needs --topic\n";
    return 2;
  }
  if (!pcd_paths.empty()) assumeCameraFrame(values, params);
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
  FrameWriter writer(params, out);
  return pcd_paths.empty() ? detectInBag(bag_path, topic, world_frame, camera_info_topic, writer)
                           : detectInPcds(pcd_paths, writer);
}
