// Small plane-geometry helpers the detector's stages share.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace hough_plane_detector
{

// Angle between two planes' normals regardless of their sign.
inline double unsignedAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return std::acos(std::min(1.0, std::abs(a.dot(b))));
}

// Nearest integer cell of continuous cell coordinates.
inline Eigen::Vector3i nearestCell(const Eigen::Vector3d& cell)
{
  return Eigen::Vector3i(static_cast<int>(std::lround(cell.x())), static_cast<int>(std::lround(cell.y())),
                         static_cast<int>(std::lround(cell.z())));
}

}  // namespace hough_plane_detector
