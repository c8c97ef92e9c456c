// The sensors' depth noise curves and the projection read from a cloud.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hough_plane_detector/core/sensor_model.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

TEST(SensorModel, NoiseCurvesFollowTheirPublishedFormulas)
{
  // Paper 4.3: 63.8 mm at 5 m with C = 1.
  EXPECT_NEAR(kinectNoiseSigma(5.0, 1.0), 0.0638, 0.0005);
  EXPECT_NEAR(kinectNoiseSigma(1.0, 0.0), 0.0027011, 1e-7);
  const DepthNoiseModel kinect(kKinectV1, 1.0);
  EXPECT_NEAR(kinect.quantizationStep(5.0), 25.0 / (580.0 * 0.075 * 8.0), 1e-9);  // 1/8 px of disparity
  EXPECT_GT(kinect.sigma(5.0), kinectNoiseSigma(5.0, 1.0));                       // plus quantization
  EXPECT_EQ(DepthNoiseModel(kKinectV1, 0.0).sigma(5.0), 0.0);
  // A wider lens makes the disparity steps coarser.
  EXPECT_NEAR(DepthNoiseModel(kKinectV1, 1.0, 290.0).quantizationStep(5.0), 2.0 * kinect.quantizationStep(5.0), 1e-9);
  // D400: z^2 * 0.08 px / (f * 50 mm); no structured-light steps.
  EXPECT_NEAR(DepthNoiseModel(kRealsenseD400, 1.0).sigma(2.0), 4.0 * 0.08 / (385.0 * 0.05), 1e-9);
  EXPECT_EQ(DepthNoiseModel(kRealsenseD400, 1.0).quantizationStep(2.0), 0.0);
  // Time of flight: 1.5 - 0.5 z + 0.3 z^2 mm.
  EXPECT_NEAR(DepthNoiseModel(kTof, 1.0).sigma(1.0), 0.0013, 1e-9);
  EXPECT_NEAR(DepthNoiseModel(kTof, 1.0).sigma(4.0), 0.0043, 1e-9);
  int model = -1;
  EXPECT_TRUE(parseSensorModel("realsense_d400", &model));
  EXPECT_EQ(model, kRealsenseD400);
  EXPECT_TRUE(parseSensorModel("3", &model));
  EXPECT_EQ(model, kTof);
  EXPECT_FALSE(parseSensorModel("kinect", &model));
  EXPECT_EQ(model, kTof);
  EXPECT_STREQ(sensorModelName(kXtion), "xtion");
}

TEST(SensorModel, FocalLengthComesFromTheCloud)
{
  Scene scene;
  scene.addRectangle({3.0, 0, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 5.0, 5.0, "wall");
  const Eigen::Isometry3d pose = lookAt({0, 0, 1.0}, {3.0, 0.4, 0.8});
  KinectNoise kinect;
  CameraIntrinsics wide;
  wide.fx = wide.fy = 385.0;
  wide.cx = 322.0;
  EXPECT_NEAR(estimateFocalLength(SceneRenderer(scene, wide).render(pose, kinect, 5).view()), 385.0, 1.0);
  // A QVGA cloud of a Kinect: 290 px at 320 wide is the sensor's 580 at 640.
  CameraIntrinsics qvga;
  qvga.width = 320;
  qvga.height = 240;
  qvga.fx = qvga.fy = 290.0;
  qvga.cx = 159.5;
  qvga.cy = 119.5;
  EXPECT_NEAR(estimateFocalLength(SceneRenderer(scene, qvga).render(pose, kinect, 5).view()), 580.0, 2.0);
  // Points that are no pinhole projection (columns shuffled) have no focal length.
  RenderedFrame shuffled = SceneRenderer(scene).render(pose, kinect, 5);
  for (int v = 0; v < shuffled.height; ++v)
    for (int u = 0; u < shuffled.width / 2; u += 3)
      for (int c = 0; c < 3; ++c)
        std::swap(shuffled.xyz[(v * shuffled.width + u) * 3 + c],
                  shuffled.xyz[(v * shuffled.width + shuffled.width - 1 - u) * 3 + c]);
  EXPECT_EQ(estimateFocalLength(shuffled.view()), 0.0);
}
