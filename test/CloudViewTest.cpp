#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "hough_plane_detector/core/cloud_view.h"

using namespace hough_plane_detector;

namespace
{
// The reason makeCloudView gives for refusing a layout; empty when it accepts it.
std::string viewError(const PointBufferLayout& layout, CloudView& view, std::vector<float>& converted)
{
  std::string error;
  if (makeCloudView(layout, view, converted, &error)) return std::string();
  EXPECT_FALSE(error.empty()) << "refused without a reason";
  return error;
}
}  // namespace

namespace
{
// A 4 x 2 cloud laid out like a driver would: x y z padding rgb, point_step 32, row padding.
struct DriverCloud
{
  PointBufferLayout layout;
  std::vector<uint8_t> data;

  DriverCloud(uint8_t datatype = 7, size_t size = 4)
  {
    layout.width = 4;
    layout.height = 2;
    layout.point_step = 32;
    layout.row_step = 4 * 32 + 16;
    layout.fields = {{"x", 0, datatype, 1}, {"y", uint32_t(size), datatype, 1}, {"z", uint32_t(2 * size), datatype, 1},
                     {"rgb", 16, 7, 1}};
    data.assign(layout.row_step * layout.height, 0xAB);
    for (uint32_t v = 0; v < 2; ++v)
      for (uint32_t u = 0; u < 4; ++u)
        for (int axis = 0; axis < 3; ++axis)
        {
          const double value = 100 * v + 10 * u + axis;
          uint8_t* p = &data[v * layout.row_step + u * layout.point_step + axis * size];
          if (datatype == 7)
          {
            const float f = static_cast<float>(value);
            std::memcpy(p, &f, 4);
          }
          else if (datatype == 8)
          {
            std::memcpy(p, &value, 8);
          }
          else if (datatype == 3)
          {
            const int16_t i = static_cast<int16_t>(value);
            std::memcpy(p, &i, 2);
          }
        }
    layout.data = data.data();
    layout.data_size = data.size();
  }
};

void expectPoints(const CloudView& view)
{
  for (int v = 0; v < 2; ++v)
    for (int u = 0; u < 4; ++u)
    {
      float x, y, z;
      view.point(u, v, x, y, z);
      EXPECT_FLOAT_EQ(x, 100 * v + 10 * u);
      EXPECT_FLOAT_EQ(y, 100 * v + 10 * u + 1);
      EXPECT_FLOAT_EQ(z, 100 * v + 10 * u + 2);
    }
}
}  // namespace

TEST(CloudView, ReadsAPaddedFloatCloudInPlace)
{
  DriverCloud cloud;
  CloudView view;
  std::vector<float> converted;
  ASSERT_TRUE(makeCloudView(cloud.layout, view, converted));
  EXPECT_EQ(view.data, cloud.data.data());  // zero copy
  EXPECT_TRUE(converted.empty());
  expectPoints(view);
}

TEST(CloudView, ConvertsOtherDatatypes)
{
  for (auto [datatype, size] : {std::pair<uint8_t, size_t>{8, 8}, {3, 2}})
  {
    DriverCloud cloud(datatype, size);
    CloudView view;
    std::vector<float> converted;
    ASSERT_TRUE(makeCloudView(cloud.layout, view, converted)) << int(datatype);
    EXPECT_NE(view.data, cloud.data.data());
    expectPoints(view);
  }
}

TEST(CloudView, RefusesBrokenLayoutsNamingTheProblem)
{
  CloudView view;
  std::vector<float> converted;
  {
    DriverCloud cloud;
    cloud.layout.fields.erase(cloud.layout.fields.begin() + 2);  // no z
    EXPECT_NE(viewError(cloud.layout, view, converted).find("no field z"), std::string::npos);
  }
  {
    DriverCloud cloud;
    cloud.layout.width = 0;
    EXPECT_NE(viewError(cloud.layout, view, converted).find("empty"), std::string::npos);
  }
  {
    DriverCloud cloud;
    cloud.layout.row_step = 100;  // < width * point_step
    EXPECT_NE(viewError(cloud.layout, view, converted).find("row_step"), std::string::npos);
  }
  {
    DriverCloud cloud;
    cloud.layout.data_size -= 1;
    EXPECT_NE(viewError(cloud.layout, view, converted).find("data holds"), std::string::npos);
  }
  {
    DriverCloud cloud;
    cloud.layout.point_step = 8;  // z at offset 8 does not fit
    cloud.layout.row_step = 32;
    EXPECT_NE(viewError(cloud.layout, view, converted).find("point_step"), std::string::npos);
  }
  {
    DriverCloud cloud;
    cloud.layout.fields[0].datatype = 42;
    EXPECT_NE(viewError(cloud.layout, view, converted).find("unknown datatype"), std::string::npos);
  }
  {
    DriverCloud cloud;
    cloud.layout.is_bigendian = true;
    EXPECT_NE(viewError(cloud.layout, view, converted).find("big-endian"), std::string::npos);
  }
}
