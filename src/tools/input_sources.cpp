#include "hough_plane_detector/tools/input_sources.h"
#include "hough_plane_detector/tools/pcd_header.h"

#include <fstream>

#include <pcl/io/pcd_io.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

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

struct BagFrameSource::Impl
{
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> view;
  rosbag::View::iterator it;
  tf2::BufferCore buffer{ros::Duration(1e6)};  // the whole bag stays queryable
  std::string world_frame;
};

BagFrameSource::BagFrameSource() : impl_(new Impl) {}
BagFrameSource::~BagFrameSource() = default;

bool BagFrameSource::open(const std::string& path, const std::string& topic, const std::string& world_frame,
                          std::string* error)
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
  impl_->world_frame = world_frame;
  try
  {
    rosbag::View all(impl_->bag);
    bool found = false;
    std::string topics;
    for (const rosbag::ConnectionInfo* c : all.getConnections())
    {
      topics += " " + c->topic + " (" + c->datatype + ")";
      if (c->topic != topic) continue;
      if (c->datatype != "sensor_msgs/PointCloud2")
      {
        if (error) *error = "topic " + topic + " in " + path + " has type " + c->datatype + ", not sensor_msgs/PointCloud2";
        return false;
      }
      found = true;
    }
    if (!found)
    {
      if (error) *error = "topic " + topic + " is not in " + path + "; it has:" + (topics.empty() ? " nothing" : topics);
      return false;
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
    impl_->view.reset(new rosbag::View(impl_->bag, rosbag::TopicQuery(topic)));
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
    frame.cloud = m.instantiate<sensor_msgs::PointCloud2>();
    if (!frame.cloud) continue;
    const std::string& source = frame.cloud->header.frame_id;
    if (source.empty())
    {
      frame.transform_error = "cloud has an empty frame_id";
      return true;
    }
    if (source == impl_->world_frame)
    {
      frame.has_transform = true;
      return true;
    }
    try
    {
      const geometry_msgs::TransformStamped t =
          impl_->buffer.lookupTransform(impl_->world_frame, source, frame.cloud->header.stamp);
      const auto& q = t.transform.rotation;
      const auto& p = t.transform.translation;
      frame.camera_to_world = Eigen::Translation3d(p.x, p.y, p.z) * Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
      frame.has_transform = true;
    }
    catch (const tf2::TransformException& e)
    {
      frame.transform_error = std::string("no transform from ") + source + " to " + impl_->world_frame + " at " +
                              std::to_string(frame.cloud->header.stamp.toSec()) + ": " + e.what();
    }
    return true;
  }
  return false;
}

}  // namespace hough_plane_detector
