#include "hough_plane_detector/tools/input_sources.h"
#include "hough_plane_detector/tools/pcd_header.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include <pcl/io/pcd_io.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include "hough_plane_detector/core/depth_image.h"
#include "hough_plane_detector/ros/frame_id.h"

namespace hough_plane_detector
{

PointBufferLayout layoutOf(const pcl::PCLPointCloud2& cloud)
{
  return layoutOfCloud(cloud);
}

bool loadPcd(const std::string& path, pcl::PCLPointCloud2& cloud, std::string* error)
{
  std::ifstream file(path, std::ios::binary);
  if (!file.good())
  {
    if (error) *error = path + ": cannot open file";
    return false;
  }
  const std::string header_problem = checkPcdHeader(file);
  if (!header_problem.empty())
  {
    if (error) *error = path + ": " + header_problem;
    return false;
  }
  pcl::PCDReader reader;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version;
  if (reader.read(path, cloud, origin, orientation, version) < 0)
  {
    if (error) *error = path + ": not a readable PCD file";
    return false;
  }
  return true;
}

bool depthImageToCloud(const sensor_msgs::Image& image, const sensor_msgs::CameraInfo& info,
                       sensor_msgs::PointCloud2& cloud, std::string* error)
{
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  const bool millimetres = image.encoding == "16UC1" || image.encoding == "mono16";
  const bool metres = image.encoding == "32FC1";
  if (!millimetres && !metres)
    return fail("depth image encoding '" + image.encoding + "' is not a depth (16UC1 or mono16 in mm, 32FC1 in m)");
  if (image.is_bigendian) return fail("big-endian depth images are not read");
  const double fx = info.K[0], fy = info.K[4], cx = info.K[2], cy = info.K[5];
  if (!(fx > 0.0 && fy > 0.0) || !std::isfinite(cx + cy))
    return fail("camera_info has no focal length (K = 0: an uncalibrated or empty camera_info)");
  if (info.width != 0 && (info.width != image.width || info.height != image.height))
    return fail("depth image of " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                " does not match its camera_info of " + std::to_string(info.width) + " x " + std::to_string(info.height));
  const size_t bytes_per_pixel = millimetres ? 2 : 4;
  if (image.width == 0 || image.height == 0 || image.step < image.width * bytes_per_pixel ||
      image.data.size() < static_cast<size_t>(image.step) * image.height)
    return fail("depth image of " + std::to_string(image.width) + " x " + std::to_string(image.height) + ", step " +
                std::to_string(image.step) + " holds " + std::to_string(image.data.size()) + " bytes: too few");
  CameraIntrinsics k;
  k.width = static_cast<int>(image.width);
  k.height = static_cast<int>(image.height);
  k.fx = fx;
  k.fy = fy;
  k.cx = cx;
  k.cy = cy;
  k.min_range = 0.0;  // the driver already dropped what its sensor does not measure
  k.max_range = std::numeric_limits<double>::infinity();
  std::vector<float> points;
  if (millimetres)
    depthImageToPoints(reinterpret_cast<const uint16_t*>(image.data.data()), k.width, k.height, image.step, k, 0.001, points);
  else
    depthImageToPoints(reinterpret_cast<const float*>(image.data.data()), k.width, k.height, image.step, k, points);
  cloud = sensor_msgs::PointCloud2();
  cloud.header = image.header;
  cloud.width = image.width;
  cloud.height = image.height;
  cloud.point_step = 12;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = false;
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
  {
    sensor_msgs::PointField field;
    field.name = names[i];
    field.offset = 4 * i;
    field.datatype = sensor_msgs::PointField::FLOAT32;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.data.resize(points.size() * sizeof(float));
  std::memcpy(cloud.data.data(), points.data(), cloud.data.size());
  return true;
}

struct BagFrameSource::Impl
{
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> view;
  rosbag::View::iterator it;
  tf2::BufferCore buffer{ros::Duration(1e6)};  // the whole bag stays queryable
  std::string world_frame;
  std::string topic, camera_info_topic;  // camera_info_topic set for a depth-image topic
  sensor_msgs::CameraInfo::ConstPtr camera_info;  // the latest one read
};

BagFrameSource::BagFrameSource() : impl_(new Impl) {}
BagFrameSource::~BagFrameSource() = default;

bool BagFrameSource::open(const std::string& path, const std::string& topic, const std::string& world_frame,
                          std::string* error, const std::string& camera_info_topic)
{
  if (!std::ifstream(path).good())
  {
    if (error) *error = path + ": cannot open file";
    return false;
  }
  try
  {
    impl_->bag.open(path, rosbag::bagmode::Read);
  }
  catch (const rosbag::BagException& e)
  {
    if (error) *error = path + ": not a readable rosbag (" + e.what() + ")";
    return false;
  }
  impl_->world_frame = tf2FrameId(world_frame);
  impl_->topic = topic;
  try
  {
    rosbag::View all(impl_->bag);
    std::string topics, type, info_type;
    const std::string info_topic =
        !camera_info_topic.empty() ? camera_info_topic : topic.substr(0, topic.find_last_of('/') + 1) + "camera_info";
    for (const rosbag::ConnectionInfo* c : all.getConnections())
    {
      topics += " " + c->topic + " (" + c->datatype + ")";
      if (c->topic == topic) type = c->datatype;
      if (c->topic == info_topic) info_type = c->datatype;
    }
    if (type.empty())
    {
      if (error) *error = "topic " + topic + " is not in " + path + "; it has:" + (topics.empty() ? " nothing" : topics);
      return false;
    }
    if (type != "sensor_msgs/PointCloud2" && type != "sensor_msgs/Image")
    {
      if (error) *error = "topic " + topic + " in " + path + " has type " + type + ", not sensor_msgs/PointCloud2 or sensor_msgs/Image";
      return false;
    }
    if (type == "sensor_msgs/Image")
    {
      if (info_type != "sensor_msgs/CameraInfo")
      {
        if (error)
          *error = "depth image topic " + topic + " needs its camera_info: " + info_topic +
                   (info_type.empty() ? " is not in " + path : " has type " + info_type) + " (give --camera-info TOPIC)";
        return false;
      }
      impl_->camera_info_topic = info_topic;
    }
    rosbag::View tf_view(impl_->bag, rosbag::TopicQuery(std::vector<std::string>{"/tf", "/tf_static"}));
    for (const rosbag::MessageInstance& m : tf_view)
    {
      tf2_msgs::TFMessage::ConstPtr tf = m.instantiate<tf2_msgs::TFMessage>();
      if (!tf) continue;
      const bool is_static = m.getTopic() == "/tf_static";
      for (const auto& t : tf->transforms)
      {
        try
        {
          impl_->buffer.setTransform(t, "bag", is_static);
        }
        catch (const std::exception&)
        {
          // A malformed transform is skipped; frames needing it report the missing transform.
        }
      }
    }
    std::vector<std::string> read{topic};
    if (!impl_->camera_info_topic.empty()) read.push_back(impl_->camera_info_topic);
    impl_->view.reset(new rosbag::View(impl_->bag, rosbag::TopicQuery(read)));
    impl_->it = impl_->view->begin();
  }
  catch (const rosbag::BagException& e)
  {
    if (error) *error = path + ": error while reading the bag (" + e.what() + ")";
    return false;
  }
  return true;
}

bool BagFrameSource::next(BagFrame& frame)
{
  while (impl_->it != impl_->view->end())
  {
    const rosbag::MessageInstance m = *impl_->it;  // a copy: the iterator owns what it points to
    ++impl_->it;
    frame = BagFrame();
    if (!impl_->camera_info_topic.empty())
    {
      if (m.getTopic() == impl_->camera_info_topic)
      {
        if (const auto info = m.instantiate<sensor_msgs::CameraInfo>()) impl_->camera_info = info;
        continue;
      }
      const sensor_msgs::Image::ConstPtr image = m.instantiate<sensor_msgs::Image>();
      if (!image) continue;
      sensor_msgs::PointCloud2::Ptr cloud(new sensor_msgs::PointCloud2);
      std::string why = "no camera_info on " + impl_->camera_info_topic + " before this image";
      if (impl_->camera_info && depthImageToCloud(*image, *impl_->camera_info, *cloud, &why))
        frame.cloud = cloud;
      if (!frame.cloud)
      {
        cloud->header = image->header;  // the frame still has its stamp and frame id
        frame.cloud = cloud;
        frame.skip_reason = "depth image refused: " + why;
        return true;
      }
    }
    else
    {
      frame.cloud = m.instantiate<sensor_msgs::PointCloud2>();
      if (!frame.cloud) continue;
    }
    const std::string source = tf2FrameId(frame.cloud->header.frame_id);
    if (source.empty())
    {
      frame.skip_reason = "cloud has an empty frame_id";
      return true;
    }
    if (source == impl_->world_frame)
    {
      frame.usable = true;
      return true;
    }
    try
    {
      const geometry_msgs::TransformStamped t =
          impl_->buffer.lookupTransform(impl_->world_frame, source, frame.cloud->header.stamp);
      const auto& q = t.transform.rotation;
      const auto& p = t.transform.translation;
      frame.camera_to_world = Eigen::Translation3d(p.x, p.y, p.z) * Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
      frame.usable = true;
    }
    catch (const tf2::TransformException& e)
    {
      frame.skip_reason = std::string("no transform from ") + source + " to " + impl_->world_frame + " at " +
                          std::to_string(frame.cloud->header.stamp.toSec()) + ": " + e.what();
    }
    return true;
  }
  return false;
}

}  // namespace hough_plane_detector
