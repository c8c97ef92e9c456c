// Small plane-geometry helpers the detector's stages share.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace hough_plane_detector
{

// Angle between two planes' normals regardless of their sign.
inline double unsignedAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return std::acos(std::min(1.0, std::abs(a.dot(b))));
}

// With the world's up known (REP 103: +z up), "level" means two things. A surface one walks on
// or sets things on lies within 26 deg of level, ramps included; gravity's own direction, which
// keeps such surfaces parallel to a fraction of a degree (floor, treads, table and shelf tops),
// is the vertical within half the merge angle, as one map's level planes are.
constexpr double kLevelSurfaceCosine = 0.9;  // cos 26 deg
inline bool isLevelSurfaceNormal(const Eigen::Vector3d& world_normal)
{
  return std::abs(world_normal.z()) >= kLevelSurfaceCosine;
}
inline bool isGravityNormal(const Eigen::Vector3d& world_normal, double merge_angle)
{
  return unsignedAngle(world_normal, Eigen::Vector3d::UnitZ()) <= merge_angle / 2.0;
}

// Eq. 7-8: two planes are one when both their normals' angle and their offsets' difference
// (after aligning the normals' signs) are under the merge tolerances.
inline bool withinMergeTolerances(const Eigen::Vector3d& normal_a, double d_a, const Eigen::Vector3d& normal_b,
                                  double d_b, double merge_angle, double merge_distance)
{
  const double sign = normal_a.dot(normal_b) >= 0.0 ? 1.0 : -1.0;
  return unsignedAngle(normal_a, normal_b) < merge_angle && std::abs(d_a - sign * d_b) < merge_distance;
}

// Nearest integer cell of continuous cell coordinates.
inline Eigen::Vector3i nearestCell(const Eigen::Vector3d& cell)
{
  return Eigen::Vector3i(static_cast<int>(std::lround(cell.x())), static_cast<int>(std::lround(cell.y())),
                         static_cast<int>(std::lround(cell.z())));
}

// The smallest value whose own and smaller values' weights reach half of `total` (their sum):
// by selection rather than a sort, as the snap runs it for every candidate. Reorders `values`;
// NaN when there are none.
inline double weightedMedian(std::vector<std::pair<double, double>>& values, double total)
{
  if (values.empty()) return std::nan("");
  auto first = values.begin(), last = values.end();
  double below = 0.0;  // weight of the values before `first`, all smaller
  while (last - first > 1)
  {
    const auto middle = first + (last - first) / 2;
    std::nth_element(first, middle, last);
    double lower = below;
    for (auto it = first; it != middle; ++it) lower += it->second;
    if (lower >= 0.5 * total)
      last = middle;
    else if (lower + middle->second >= 0.5 * total)
      return middle->first;
    else
    {
      below = lower + middle->second;
      first = middle + 1;
    }
  }
  if (first != values.end() && below + first->second >= 0.5 * total) return first->first;
  return std::max_element(values.begin(), values.end())->first;
}

}  // namespace hough_plane_detector
