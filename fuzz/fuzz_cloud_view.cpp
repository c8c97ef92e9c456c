// libFuzzer target: arbitrary PointCloud2 layouts and data through makeCloudView and, when they
// are accepted, through the whole detector. Any crash, leak or undefined behaviour is a bug.
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "hough_plane_detector/core/plane_detector.h"

using namespace hough_plane_detector;

namespace
{
template <class T>
T take(const uint8_t*& data, size_t& size)
{
  T value{};
  const size_t n = std::min(size, sizeof(T));
  std::memcpy(&value, data, n);
  data += n;
  size -= n;
  return value;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
  static std::unique_ptr<PlaneDetector> detector = [] {
    DetectorParams params;
    params.resolution = 256;  // a small space: the fuzzer runs many frames
    params.normal_window = 8;
    params.normal_stride = 8;
    params.min_support = 10;
    return std::unique_ptr<PlaneDetector>(new PlaneDetector(params));
  }();
  // Header: small sizes so each input stays fast; fields from the input too.
  PointBufferLayout layout;
  layout.width = take<uint8_t>(data, size);
  layout.height = take<uint8_t>(data, size);
  layout.point_step = take<uint8_t>(data, size);
  layout.row_step = take<uint16_t>(data, size);
  layout.is_bigendian = take<uint8_t>(data, size) & 1;
  const int field_count = take<uint8_t>(data, size) % 6;
  const char* names[] = {"x", "y", "z", "rgb", "intensity", "x"};
  for (int i = 0; i < field_count; ++i)
  {
    PointFieldLayout field;
    field.name = names[take<uint8_t>(data, size) % 6];
    field.offset = take<uint8_t>(data, size);
    field.datatype = take<uint8_t>(data, size) % 10;
    field.count = 1;
    layout.fields.push_back(field);
  }
  std::vector<uint8_t> buffer(data, data + size);
  layout.data = buffer.data();
  layout.data_size = buffer.size();
  CloudView view;
  std::vector<float> converted;
  if (!makeCloudView(layout, view, converted)) return 0;
  std::string error;
  detector->processFrame(view, Eigen::Isometry3d::Identity(), 0.0, &error);
  return 0;
}
