// A read-only view of an organized point buffer (a PointCloud2 or PCL PCLPointCloud2 data
// block) that the detector reads in place, so a driver's message is never copied.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace hough_plane_detector
{

struct CloudView
{
  const uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  size_t point_step = 0;
  size_t row_step = 0;
  size_t x_offset = 0;
  size_t y_offset = 4;
  size_t z_offset = 8;

  // Reads point (u, v); memcpy because a driver's padding may leave floats unaligned.
  void point(int u, int v, float& x, float& y, float& z) const
  {
    const uint8_t* p = data + static_cast<size_t>(v) * row_step + static_cast<size_t>(u) * point_step;
    std::memcpy(&x, p + x_offset, sizeof(float));
    std::memcpy(&y, p + y_offset, sizeof(float));
    std::memcpy(&z, p + z_offset, sizeof(float));
  }
  size_t size() const { return static_cast<size_t>(width) * height; }
};

// Field datatypes, numbered as sensor_msgs/PointField and pcl::PCLPointField.
enum class PointDatatype : uint8_t
{
  kInt8 = 1, kUInt8 = 2, kInt16 = 3, kUInt16 = 4, kInt32 = 5, kUInt32 = 6, kFloat32 = 7, kFloat64 = 8
};

struct PointFieldLayout
{
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 1;
};

// The layout of a PointCloud2-like buffer, filled from a ROS message or a PCL cloud.
struct PointBufferLayout
{
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  bool is_bigendian = false;
  std::vector<PointFieldLayout> fields;
  const uint8_t* data = nullptr;
  size_t data_size = 0;
};

// The layout of any PointCloud2-shaped cloud (sensor_msgs::PointCloud2, pcl::PCLPointCloud2):
// both name their members the same way.
template <class Cloud>
PointBufferLayout layoutOfCloud(const Cloud& cloud)
{
  PointBufferLayout layout;
  layout.width = cloud.width;
  layout.height = cloud.height;
  layout.point_step = cloud.point_step;
  layout.row_step = cloud.row_step;
  layout.is_bigendian = cloud.is_bigendian;
  for (const auto& f : cloud.fields) layout.fields.push_back(PointFieldLayout{f.name, f.offset, f.datatype, f.count});
  layout.data = cloud.data.data();
  layout.data_size = cloud.data.size();
  return layout;
}

// Checks the layout and makes a view of it. Float32 x/y/z are viewed in place; other numeric
// types are converted into `converted`, which must outlive the view. Returns false, with what is
// wrong with the buffer in `error`, when it cannot be viewed.
bool makeCloudView(const PointBufferLayout& layout, CloudView& view, std::vector<float>& converted,
                   std::string* error = nullptr);

}  // namespace hough_plane_detector
