#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "hough_plane_detector/core/depth_image.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

TEST(DepthImage, ReproducesTheRenderersPointsFromMillimetreDepth)
{
  Scene scene;
  scene.addRectangle({3.0, 0, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 5.0, 5.0, "wall");
  scene.addRectangle({0, 0, 0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 8.0, 8.0, "floor");
  KinectNoise exact;
  exact.gaussian = false;
  exact.quantize = false;
  const SceneRenderer renderer(scene);
  const RenderedFrame frame = renderer.render(lookAt({0, 0, 1.0}, {3.0, 0.5, 0.5}), exact, 1);
  // The frame as a Kinect would give it: 16-bit millimetres, rows padded to 1288 bytes.
  const size_t stride = 1288;
  std::vector<uint8_t> image(stride * frame.height, 0);
  for (int v = 0; v < frame.height; ++v)
    for (int u = 0; u < frame.width; ++u)
    {
      const float z = frame.xyz[(v * frame.width + u) * 3 + 2];
      const uint16_t mm = std::isfinite(z) ? static_cast<uint16_t>(std::lround(z * 1000.0)) : 0;
      std::memcpy(&image[v * stride + u * 2], &mm, 2);
    }
  std::vector<float> points;
  depthImageToPoints(reinterpret_cast<const uint16_t*>(image.data()), frame.width, frame.height, stride,
                     renderer.intrinsics(), 0.001, points);
  ASSERT_EQ(points.size(), frame.xyz.size());
  int valid = 0;
  for (size_t i = 0; i < points.size(); i += 3)
  {
    ASSERT_EQ(std::isfinite(points[i + 2]), std::isfinite(frame.xyz[i + 2])) << "pixel " << i / 3;
    if (!std::isfinite(points[i + 2])) continue;
    ++valid;
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(points[i + a], frame.xyz[i + a], 0.002);  // millimetre rounding
  }
  EXPECT_GT(valid, 300000);
}

TEST(DepthImage, ZeroAndOutOfRangeDepthsAreNoReturn)
{
  CameraIntrinsics k = intrinsicsFromFieldOfView(4, 2, 1.0226, 0.7959);  // Kinect-like 58.6 x 45.6 deg
  EXPECT_NEAR(k.fx, 4 / (2 * std::tan(1.0226 / 2)), 1e-9);
  const uint16_t depth[8] = {0, 1000, 200, 65000, 1500, 1500, 1500, 1500};
  std::vector<float> points;
  depthImageToPoints(depth, 4, 2, 8, k, 0.001, points);
  EXPECT_TRUE(std::isnan(points[2]));   // 0: no return
  EXPECT_FLOAT_EQ(points[5], 1.0f);
  EXPECT_TRUE(std::isnan(points[8]));   // 0.2 m: nearer than min_range
  EXPECT_TRUE(std::isnan(points[11]));  // 65 m: beyond max_range
  EXPECT_FLOAT_EQ(points[14], 1.5f);
  EXPECT_NEAR(points[12], (0 - k.cx) / k.fx * 1.5, 1e-6);
  EXPECT_NEAR(points[13], (1 - k.cy) / k.fy * 1.5, 1e-6);
}
