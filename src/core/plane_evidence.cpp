#include "hough_plane_detector/core/plane_evidence.h"

#include <algorithm>
#include <cmath>

namespace hough_plane_detector
{

namespace
{
constexpr double kMinDepth = 0.3;          // m: nearer than any depth sensor measures
constexpr double kMinRayCosine = 0.2;      // rays within ~12 deg of the plane graze it: no test
constexpr double kSystematicMargin = 0.02;  // m beyond 3 sigma: calibration residue, a slightly bent surface
}  // namespace

PlaneEvidence checkPlaneEvidence(const PlaneExtent& extent, const Eigen::Vector3d& normal, double d,
                                 const CloudView& cloud, const Eigen::Isometry3d& camera_to_world,
                                 const PinholeIntrinsics& k, const DepthNoiseModel& noise, int64_t frame,
                                 float fade_per_frame)
{
  PlaneEvidence evidence;
  if (!k.valid()) return evidence;
  const Eigen::Isometry3d world_to_camera = camera_to_world.inverse();
  const Eigen::Vector3d n_cam = world_to_camera.linear() * normal;
  const double d_cam = d - n_cam.dot(world_to_camera.translation());
  // A 10 cm lattice of the extent's 5 cm cells: as conclusive, a quarter of the work.
  constexpr int kCellStride = 2;
  extent.forEachLiveCell(frame, fade_per_frame, kCellStride, [&](const Eigen::Vector3d& centre) {
    const Eigen::Vector3d c = world_to_camera * centre;
    if (c.z() < kMinDepth) return;
    const int u = static_cast<int>(std::lround(k.fx * c.x() / c.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * c.y() / c.z() + k.cy));
    if (u < 0 || v < 0 || u >= cloud.width || v >= cloud.height) return;
    // Where this pixel's ray meets the plane (the cell's centre picked the pixel only).
    const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
    const double along = n_cam.dot(ray);
    if (std::abs(along) < kMinRayCosine * ray.norm()) return;
    const double expected = -d_cam / along;
    if (!(expected > kMinDepth)) return;
    float x, y, z;
    cloud.point(u, v, x, y, z);
    if (!std::isfinite(z) || z <= 0.0f) return;  // no return: no evidence
    const double tolerance = 3.0 * noise.sigma(expected) + kSystematicMargin;
    if (std::abs(z - expected) <= tolerance)
      ++evidence.confirmed;
    else if (z > expected + tolerance)
      ++evidence.contradicted;  // the ray went through where the plane should be
    // else: something in front of it hides it
  });
  return evidence;
}

bool PlaneBelief::update(const PlaneEvidence& evidence)
{
  if (evidence.confirmed + evidence.contradicted < kMinCells) return false;
  if (evidence.contradicted > evidence.confirmed)
  {
    ++contradictions;
    log_odds = std::max(kMin, log_odds + kMiss);
  }
  else
  {
    ++confirmations;
    log_odds = std::min(kMax, log_odds + kHit);
  }
  return true;
}

}  // namespace hough_plane_detector
