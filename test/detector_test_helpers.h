// Helpers of the detector's tests: noise, matching planes, feeding frames, describing maps.
#pragma once

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

namespace
{
const Eigen::Vector3d kX = Eigen::Vector3d::UnitX(), kY = Eigen::Vector3d::UnitY(), kZ = Eigen::Vector3d::UnitZ();

KinectNoise kinect(double c)
{
  KinectNoise noise;
  noise.coefficient = c;
  return noise;
}

// Detected planes that are (n, d) within the tolerances, whatever their sign.
std::vector<const DetectedPlane*> matching(const std::vector<DetectedPlane>& planes, const Eigen::Vector3d& n, double d,
                                           double angle_tol, double d_tol)
{
  std::vector<const DetectedPlane*> out;
  for (const auto& p : planes)
    if (angleError(p.normal, n) <= angle_tol && distanceError(p.normal, p.d, n, d) <= d_tol) out.push_back(&p);
  return out;
}

void feed(PlaneDetector& detector, const RenderedFrame& frame, double stamp)
{
  std::string error;
  ASSERT_TRUE(detector.processFrame(frame.view(), frame.camera_to_world, stamp, &error)) << error;
}

std::string describe(const std::vector<DetectedPlane>& planes)
{
  std::string s;
  for (const auto& p : planes)
    s += "\n  id " + std::to_string(p.id) + " n=(" + std::to_string(p.normal.x()) + ", " + std::to_string(p.normal.y()) +
         ", " + std::to_string(p.normal.z()) + ") d=" + std::to_string(p.d) + " strength " + std::to_string(p.strength);
  return s;
}
}  // namespace
