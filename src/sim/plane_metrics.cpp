#include "hough_plane_detector/sim/plane_metrics.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace hough_plane_detector
{

double angleError(const Eigen::Vector3d& normal, const Eigen::Vector3d& true_normal)
{
  return std::acos(std::min(1.0, std::abs(normal.normalized().dot(true_normal.normalized()))));
}

double distanceError(const Eigen::Vector3d& normal, double d, const Eigen::Vector3d& true_normal, double true_d)
{
  const double sign = normal.dot(true_normal) >= 0.0 ? 1.0 : -1.0;
  return std::abs(sign * d - true_d);
}

std::vector<EvaluatedPlane> evaluatedPlanes(const std::vector<DetectedPlane>& planes)
{
  std::vector<EvaluatedPlane> out;
  out.reserve(planes.size());
  for (const DetectedPlane& plane : planes) out.push_back({plane.normal, plane.d});
  return out;
}

const TruePlane* nearestTruePlane(const Eigen::Vector3d& normal, double d, const std::vector<TruePlane>& truth,
                                  double max_cost, const MatchTolerance& tolerance)
{
  const TruePlane* best = nullptr;
  double best_cost = max_cost;
  for (const TruePlane& t : truth)
  {
    const double cost = angleError(normal, t.normal) / tolerance.angle + distanceError(normal, d, t.normal, t.d) / tolerance.distance;
    if (cost <= best_cost)
    {
      best_cost = cost;
      best = &t;
    }
  }
  return best;
}

FrameMetrics evaluateFrame(const std::vector<TruePlane>& true_planes, const std::vector<int>& visible_points,
                           int min_visible_points, const std::vector<EvaluatedPlane>& detections,
                           const MatchTolerance& tolerance)
{
  FrameMetrics m;
  auto isVisible = [&](size_t t) { return t < visible_points.size() && visible_points[t] >= min_visible_points; };
  // Visible planes are matched first: a surface hidden in this frame that lies on the same plane
  // as a visible one (a shelf board at a table's height) must not take the visible one's detection.
  std::vector<std::tuple<bool, double, size_t, size_t>> pairs;  // hidden, cost, true, detection
  for (size_t t = 0; t < true_planes.size(); ++t)
    for (size_t k = 0; k < detections.size(); ++k)
    {
      const double ea = angleError(detections[k].normal, true_planes[t].normal);
      const double ed = distanceError(detections[k].normal, detections[k].d, true_planes[t].normal, true_planes[t].d);
      if (ea <= tolerance.angle && ed <= tolerance.distance)
        pairs.emplace_back(!isVisible(t), ea / tolerance.angle + ed / tolerance.distance, t, k);
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> true_match(true_planes.size(), -1), detection_match(detections.size(), -1);
  for (const auto& [hidden, cost, t, k] : pairs)
  {
    if (true_match[t] >= 0 || detection_match[k] >= 0) continue;
    true_match[t] = static_cast<int>(k);
    detection_match[k] = static_cast<int>(t);
  }
  for (size_t t = 0; t < true_planes.size(); ++t)
  {
    if (!isVisible(t)) continue;
    ++m.visible;
    if (true_match[t] < 0)
    {
      m.missed.push_back(static_cast<int>(t));
      continue;
    }
    ++m.detected;
    const EvaluatedPlane& det = detections[true_match[t]];
    m.angle_errors.push_back(angleError(det.normal, true_planes[t].normal));
    m.d_errors.push_back(distanceError(det.normal, det.d, true_planes[t].normal, true_planes[t].d));
  }
  for (size_t k = 0; k < detections.size(); ++k)
    if (detection_match[k] < 0)
    {
      ++m.false_detections;
      m.false_indices.push_back(static_cast<int>(k));
    }
  return m;
}

}  // namespace hough_plane_detector
