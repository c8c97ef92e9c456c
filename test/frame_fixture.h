// A rendered frame measured as the per-frame stages see it, for their tests: a floor, a wall
// 3.5 m ahead, a step before it and a pillar by default.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "hough_plane_detector/core/frame_data.h"
#include "hough_plane_detector/core/hough_parameterization.h"
#include "hough_plane_detector/core/hough_peaks.h"
#include "hough_plane_detector/core/planarity_tests.h"
#include "hough_plane_detector/sim/scene_renderer.h"

namespace hough_plane_detector
{
namespace test
{
// A floor, a wall 3.5 m ahead, a step 20 cm high and 30 cm deep before it, a pillar.
inline Scene stepScene()
{
  Scene scene;
  scene.addRectangle(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 3, 3, "floor");
  scene.addRectangle(Eigen::Vector3d(3.5, 0, 1.4), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 3, 1.4, "wall");
  scene.addBox(Eigen::Vector3d(2.0, 0.3, 0.1), Eigen::Vector3d(0.15, 0.6, 0.1), 0.0, "step");
  scene.cylinders.push_back({Eigen::Vector3d(1.6, -0.7, 0), 0.25, 2.0});
  return scene;
}

struct Frame
{
  DetectorParams params;
  HoughParameterization param{params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance, 8};
  SceneRenderer renderer;
  RenderedFrame rendered;
  FrameData frame;
  PlanarityTests tests{params, frame};

  explicit Frame(const Scene& scene = stepScene(),
                 const Eigen::Isometry3d& pose = lookAt(Eigen::Vector3d(0, 0, 1.2), Eigen::Vector3d(3, 0, 0.4)))
    : renderer(scene)
  {
    KinectNoise noise;
    rendered = renderer.render(pose, noise, 7);
    frame.measure(rendered.view(), rendered.camera_to_world, params, DepthNoiseModel(params.sensor_model, 1.0, 0.0));
    frame.block_claim.assign(frame.blocks.size(), 0);
  }
  int truePlane(const std::string& name) const
  {
    for (size_t i = 0; i < renderer.truePlanes().size(); ++i)
      if (renderer.truePlanes()[i].name == name) return static_cast<int>(i);
    return -1;
  }
  // Valid blocks whose pixels all lie on true plane `index` (-1: on clutter, the pillar here).
  std::vector<int> blocksOn(int index) const
  {
    std::vector<int> out;
    const int s = blockSize(params.normal_window, params.normal_stride);
    for (size_t b = 0; b < frame.blocks.size(); ++b)
    {
      if (!frame.blocks[b].valid) continue;
      const int bx = static_cast<int>(b) % frame.blocksX(), by = static_cast<int>(b) / frame.blocksX();
      bool all = true;
      for (int v = by * s; v < (by + 1) * s && all; ++v)
        for (int u = bx * s; u < (bx + 1) * s && all; ++u)
        {
          const size_t i = static_cast<size_t>(v) * rendered.width + u;
          all = std::isfinite(rendered.xyz[3 * i + 2]) && rendered.pixel_plane[i] == index;
        }
      if (all) out.push_back(static_cast<int>(b));
    }
    return out;
  }
  // The blocks of true plane `name` within a k x k square around the middle one of its list.
  std::vector<int> squareOn(const std::string& name, int k) const
  {
    const std::vector<int> on = blocksOn(truePlane(name));
    const int bx_count = frame.blocksX(), middle = on[on.size() / 2];
    std::vector<int> blocks;
    for (int b : on)
      if (std::abs(b % bx_count - middle % bx_count) <= k / 2 && std::abs(b / bx_count - middle / bx_count) <= k / 2)
        blocks.push_back(b);
    return blocks;
  }
  // The middle image row of the blocks.
  int wallRow(const std::vector<int>& blocks) const
  {
    int low = frame.blocksY(), high = 0;
    for (int b : blocks) low = std::min(low, b / frame.blocksX()), high = std::max(high, b / frame.blocksX());
    return (low + high) / 2;
  }
  HoughPeak peakOf(const TruePlane& truth) const
  {
    HoughPeak peak;
    peak.normal = truth.normal;
    peak.d = truth.d;
    peak.hough = param.toHough(truth.normal, truth.d);
    peak.value = 1000.0;
    return peak;
  }
};

inline double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::acos(std::min(1.0, std::abs(a.dot(b)))); }
}  // namespace test
}  // namespace hough_plane_detector
