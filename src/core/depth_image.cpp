#include "hough_plane_detector/core/depth_image.h"

#include <cmath>
#include <cstring>
#include <limits>

namespace hough_plane_detector
{

namespace
{
// One unprojection for every depth type: depth_of(row, u) gives metres, 0 or NaN for no return.
template <class Pixel, class DepthOf>
void unproject(const Pixel* depth, int width, int height, size_t row_stride, const CameraIntrinsics& k,
               DepthOf depth_of, std::vector<float>& points)
{
  points.assign(static_cast<size_t>(width) * height * 3, std::numeric_limits<float>::quiet_NaN());
  for (int v = 0; v < height; ++v)
  {
    const Pixel* row = reinterpret_cast<const Pixel*>(reinterpret_cast<const uint8_t*>(depth) + v * row_stride);
    for (int u = 0; u < width; ++u)
    {
      const double z = depth_of(row, u);
      if (!(z > 0.0) || z < k.min_range || z > k.max_range) continue;  // 0 or NaN: no return
      float* p = &points[(static_cast<size_t>(v) * width + u) * 3];
      p[0] = static_cast<float>((u - k.cx) / k.fx * z);
      p[1] = static_cast<float>((v - k.cy) / k.fy * z);
      p[2] = static_cast<float>(z);
    }
  }
}
}  // namespace

void depthImageToPoints(const uint16_t* depth, int width, int height, size_t row_stride,
                        const CameraIntrinsics& k, double metres_per_unit, std::vector<float>& points)
{
  // Rows of an image message need not be aligned: each pixel is read by value.
  unproject(reinterpret_cast<const uint8_t*>(depth), width, height, row_stride, k,
            [metres_per_unit](const uint8_t* row, int u) {
              uint16_t value;
              std::memcpy(&value, row + 2 * u, 2);
              return value * metres_per_unit;
            },
            points);
}

void depthImageToPoints(const float* metres, int width, int height, size_t row_stride, const CameraIntrinsics& k,
                        std::vector<float>& points)
{
  unproject(reinterpret_cast<const uint8_t*>(metres), width, height, row_stride, k,
            [](const uint8_t* row, int u) {
              float value;
              std::memcpy(&value, row + 4 * u, 4);
              return static_cast<double>(value);
            },
            points);
}

namespace
{
constexpr double kDisparityOffset = 3.3309495161;   // 1/m
constexpr double kDisparityScale = -0.0030711016;  // 1/m per raw unit
constexpr uint16_t kNoDisparity = 2047;
}  // namespace

uint16_t kinectDisparityToMillimetres(uint16_t raw, const CameraIntrinsics& intrinsics)
{
  if (raw >= kNoDisparity) return 0;
  const double inverse_depth = kDisparityOffset + kDisparityScale * raw;
  if (!(inverse_depth > 0.0)) return 0;
  const double metres = 1.0 / inverse_depth;
  if (metres < intrinsics.min_range || metres > intrinsics.max_range) return 0;
  return static_cast<uint16_t>(std::lround(metres * 1000.0));
}

uint16_t kinectMetresToDisparity(double metres)
{
  if (!(metres > 0.0) || !std::isfinite(metres)) return kNoDisparity;
  const double raw = (1.0 / metres - kDisparityOffset) / kDisparityScale;
  if (!(raw >= 0.0) || raw >= kNoDisparity) return kNoDisparity;
  return static_cast<uint16_t>(std::lround(raw));
}

CameraIntrinsics intrinsicsFromFieldOfView(int width, int height, double horizontal_fov, double vertical_fov)
{
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = width / (2.0 * std::tan(horizontal_fov / 2.0));
  k.fy = height / (2.0 * std::tan(vertical_fov / 2.0));
  k.cx = (width - 1) / 2.0;
  k.cy = (height - 1) / 2.0;
  k.min_range = 0.3;
  k.max_range = 10.0;
  return k;
}

}  // namespace hough_plane_detector
