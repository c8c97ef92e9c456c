#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

namespace
{
struct NoiseShares
{
  double within_block = 0.0;  // mean variance inside 8 x 8 pixel blocks, over sigma^2
  double block_means = 0.0;   // variance of the blocks' mean depths, over sigma^2
};

// A wall 2 m ahead of the camera, square to its axis: every pixel's true depth is 2 m.
NoiseShares measureWallNoise(const KinectNoise& noise)
{
  Scene scene;
  scene.addRectangle({2.0, 0.0, 1.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}, 4.0, 4.0, "wall");
  const RenderedFrame frame = SceneRenderer(scene).render(lookAt({0.0, 0.0, 1.0}, {2.0, 0.0, 1.0}), noise, 7);
  constexpr int kBlock = 8;
  double within = 0.0, mean_sum = 0.0, mean_squares = 0.0;
  int blocks = 0;
  for (int by = 0; by + kBlock <= frame.height; by += kBlock)
    for (int bx = 0; bx + kBlock <= frame.width; bx += kBlock)
    {
      double sum = 0.0, squares = 0.0;
      for (int v = by; v < by + kBlock; ++v)
        for (int u = bx; u < bx + kBlock; ++u)
        {
          const double error = frame.xyz[(static_cast<size_t>(v) * frame.width + u) * 3 + 2] - 2.0;
          sum += error;
          squares += error * error;
        }
      const double mean = sum / (kBlock * kBlock);
      within += squares / (kBlock * kBlock) - mean * mean;
      mean_sum += mean;
      mean_squares += mean * mean;
      ++blocks;
    }
  const double sigma = kinectNoiseSigma(2.0, noise.coefficient);
  NoiseShares shares;
  shares.within_block = within / blocks / (sigma * sigma);
  shares.block_means = (mean_squares / blocks - (mean_sum / blocks) * (mean_sum / blocks)) / (sigma * sigma);
  return shares;
}
}  // namespace

TEST(SceneRenderer, IndependentNoiseAveragesOutOverABlockAndCorrelatedNoiseDoesNot)
{
  KinectNoise independent;
  independent.quantize = false;
  const NoiseShares iid = measureWallNoise(independent);
  EXPECT_NEAR(iid.within_block, 63.0 / 64.0, 0.05);
  EXPECT_NEAR(iid.block_means, 1.0 / 64.0, 0.005);

  // As osd-learn's real frames measure (evaluate_osd --noise): little spread inside a block,
  // block means that keep most of the correlated share.
  KinectNoise correlated = independent;
  correlated.correlation_px = 8.0;
  correlated.correlated_variance = 0.16;
  correlated.independent_variance = 0.05;
  const NoiseShares field = measureWallNoise(correlated);
  EXPECT_GT(field.within_block, 0.04);
  EXPECT_LT(field.within_block, 0.08);
  EXPECT_GT(field.block_means, 0.11);
  EXPECT_LT(field.block_means, 0.17);
}
