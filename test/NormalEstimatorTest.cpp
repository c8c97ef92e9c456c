#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hough_plane_detector/core/normal_estimator.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "hough_plane_detector/core/sensor_model.h"

using namespace hough_plane_detector;

namespace
{
RenderedFrame renderWall(const Eigen::Isometry3d& pose, double noise)
{
  Scene scene;
  scene.addRectangle({3.0, 0, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 5.0, 5.0, "wall");
  KinectNoise kinect;
  kinect.coefficient = noise;
  kinect.quantize = noise > 0;
  kinect.gaussian = noise > 0;
  return SceneRenderer(scene).render(pose, kinect, 3);
}
}  // namespace

TEST(NormalEstimator, WindowNormalsOfAPlaneFaceTheSensorInTheWorldFrame)
{
  const Eigen::Isometry3d pose = lookAt({0.2, 0.3, 1.0}, {3.0, 1.0, 0.6});
  const RenderedFrame frame = renderWall(pose, 0.0);
  NormalEstimator estimator;
  std::vector<WindowSample> samples;
  NormalEstimatorConfig config;
  config.window = 16;
  config.stride = 8;
  estimator.compute(frame.view(), pose, config, samples);
  ASSERT_EQ(estimator.blocksX(), 80);
  ASSERT_EQ(estimator.blocksY(), 60);
  ASSERT_GT(samples.size(), 4000u);
  for (const WindowSample& s : samples)
  {
    // Wall x = 3 seen from x < 3: the normal toward the sensor is -x, d = 3.
    EXPECT_NEAR(s.normal.x(), -1.0, 1e-4);
    EXPECT_NEAR(s.d, 3.0, 1e-3);
    EXPECT_NEAR(s.centroid.x(), 3.0, 1e-3);
    EXPECT_EQ(s.count, 256);
  }
}

// Depth noise along the rays tilts plain covariance normals of an oblique wall toward the
// sensor (about 0.1 rad at 2.5 m, 45 deg, C = 1); the estimator takes that noise out.
TEST(NormalEstimator, NormalsOfAnObliqueNoisyWallAreNotTiltedTowardTheSensor)
{
  const Eigen::Isometry3d pose = lookAt({0.5, 0.0, 1.0}, {3.0, 2.5, 1.0});
  const RenderedFrame frame = renderWall(pose, 1.0);
  NormalEstimator estimator;
  std::vector<WindowSample> samples;
  estimator.compute(frame.view(), pose, NormalEstimatorConfig{32, 16, 0.6, 0.02, DepthNoiseModel(kKinectV1, 1.0), 4}, samples);
  ASSERT_GT(samples.size(), 500u);
  double sum = 0.0;
  for (const WindowSample& s : samples) sum += std::acos(std::min(1.0, std::abs(s.normal.x())));
  EXPECT_LT(sum / samples.size(), 0.03) << "mean angle error of " << samples.size() << " windows";
}

TEST(NormalEstimator, SkipsWindowsWithTooFewPointsAndCreases)
{
  // Half the image NaN, and a corner between the wall and a floor.
  Scene scene;
  scene.addRectangle({3.0, 0, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 5.0, 5.0, "wall");
  scene.addRectangle({0, 0, 0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 5.0, 5.0, "floor");
  KinectNoise clean;
  clean.coefficient = 0.0;
  clean.quantize = false;
  clean.gaussian = false;
  const Eigen::Isometry3d pose = lookAt({0.5, 0, 1.0}, {3.0, 0, 0.0});
  RenderedFrame frame = SceneRenderer(scene).render(pose, clean, 1);
  for (int v = 0; v < 480; ++v)
    for (int u = 320; u < 640; ++u)
      for (int a = 0; a < 3; ++a) frame.xyz[(v * 640 + u) * 3 + a] = std::numeric_limits<float>::quiet_NaN();
  NormalEstimator estimator;
  std::vector<WindowSample> samples;
  NormalEstimatorConfig config;
  config.window = 16;
  config.stride = 8;
  config.noise = DepthNoiseModel(kKinectV1, 0.0);
  estimator.compute(frame.view(), pose, config, samples);
  ASSERT_GT(samples.size(), 1000u);
  for (const WindowSample& s : samples)
  {
    // A window needs min_valid_fraction of its pixels, so none reaches far into the NaN half.
    EXPECT_LE(s.window_x * 8, 320 - config.min_valid_fraction * 16);
    const bool wall = std::abs(s.normal.x() + 1.0) < 1e-3, floor = std::abs(s.normal.z() - 1.0) < 1e-3;
    EXPECT_TRUE(wall || floor) << "window across the crease kept: " << s.normal.transpose();
  }
}

TEST(NormalEstimator, MomentsTransformLikeThePoints)
{
  PointMoments m;
  const Eigen::Vector3d pts[3] = {{1, 2, 3}, {-1, 0.5, 2}, {0.3, -0.7, 1}};
  const Eigen::Isometry3d t = Eigen::Translation3d(1, -2, 0.5) * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
  PointMoments moved_direct;
  for (const auto& p : pts)
  {
    for (auto [target, q] : {std::pair<PointMoments*, Eigen::Vector3d>{&m, p}, {&moved_direct, t * p}})
    {
      target->count += 1;
      target->sum += q;
      target->xx += q.x() * q.x(); target->xy += q.x() * q.y(); target->xz += q.x() * q.z();
      target->yy += q.y() * q.y(); target->yz += q.y() * q.z(); target->zz += q.z() * q.z();
    }
  }
  const PointMoments moved = m.transformed(t);
  EXPECT_NEAR((moved.sum - moved_direct.sum).norm(), 0.0, 1e-12);
  EXPECT_NEAR((moved.covariance() - moved_direct.covariance()).norm(), 0.0, 1e-12);
}

TEST(NormalEstimator, BlockMomentsDoNotDependOnThePointLayout)
{
  // Packed x y z (12 bytes), padded x y z _ (16 bytes) and x _ y _ z _ (24 bytes, read field by
  // field) are summed by different loops; with holes, a NaN in x alone and an Inf in z alone,
  // every block's moments must agree to float rounding.
  const Eigen::Isometry3d pose = lookAt({0.2, 0.3, 1.0}, {3.0, 1.0, 0.6});
  RenderedFrame frame = renderWall(pose, 1.0);
  const int pixels = frame.width * frame.height;
  for (int i = 0; i < pixels; i += 97) frame.xyz[3 * i] = std::numeric_limits<float>::quiet_NaN();
  for (int i = 5; i < pixels; i += 89) frame.xyz[3 * i + 2] = std::numeric_limits<float>::infinity();
  frame.xyz[3 * (pixels - 1)] = 0.5f;  // the cloud's last point valid: read to its very end
  std::vector<float> padded(4 * pixels, 7.0f), spread(6 * pixels, 7.0f);
  for (int i = 0; i < pixels; ++i)
    for (int c = 0; c < 3; ++c)
    {
      padded[4 * i + c] = frame.xyz[3 * i + c];
      spread[6 * i + 2 * c] = frame.xyz[3 * i + c];
    }
  CloudView packed_view = frame.view(), padded_view = packed_view, spread_view = packed_view;
  padded_view.data = reinterpret_cast<const uint8_t*>(padded.data());
  padded_view.point_step = 16;
  padded_view.row_step = 16 * frame.width;
  spread_view.data = reinterpret_cast<const uint8_t*>(spread.data());
  spread_view.point_step = 24;
  spread_view.row_step = 24 * frame.width;
  spread_view.y_offset = 8;
  spread_view.z_offset = 16;

  NormalEstimatorConfig config;
  config.window = 16;
  config.stride = 8;
  NormalEstimator packed, padded_estimator, spread_estimator;
  std::vector<WindowSample> samples;
  packed.compute(packed_view, pose, config, samples);
  padded_estimator.compute(padded_view, pose, config, samples);
  spread_estimator.compute(spread_view, pose, config, samples);
  int compared = 0;
  for (int by = 0; by < packed.blocksY(); ++by)
    for (int bx = 0; bx < packed.blocksX(); ++bx)
      for (const NormalEstimator* other : {&padded_estimator, &spread_estimator})
      {
        const PointMoments& a = packed.block(bx, by);
        const PointMoments& b = other->block(bx, by);
        ASSERT_EQ(a.count, b.count) << "block " << bx << ", " << by;
        if (a.count < 3) continue;
        EXPECT_LT((a.mean() - b.mean()).norm(), 1e-6) << "block " << bx << ", " << by;
        EXPECT_LT((a.covariance() - b.covariance()).norm(), 1e-8) << "block " << bx << ", " << by;
        ++compared;
      }
  EXPECT_GT(compared, 8000);
}
