// Where on its infinite plane a plane was seen: 5 cm cells in the plane's own 2-D coordinates,
// accumulated over frames with bounded memory, fading like the Hough space, and their convex
// hull as the polygon markers and messages show.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace hough_plane_detector
{

class PlaneExtent
{
public:
  static constexpr double kCellSize = 0.05;     // m
  static constexpr size_t kMaxCells = 40000;    // 100 m^2 of plane
  static constexpr float kMaxWeight = 20.0f;

  // Marks the cell under a world point that lies on the plane (normal, d).
  void add(const Eigen::Vector3d& normal, double d, const Eigen::Vector3d& point);
  // Every cell loses `amount`; empty cells are dropped, so the extent shrinks as a plane fades.
  void decay(float amount);
  // Convex hull of the cells, counter-clockwise about the normal, in the world frame.
  std::vector<Eigen::Vector3d> hull(const Eigen::Vector3d& normal, double d) const;
  size_t cellCount() const { return cells_.size(); }

  // For saving maps: cells as (x, y, weight).
  std::vector<std::pair<std::pair<int32_t, int32_t>, float>> cells() const;
  void setCell(int32_t x, int32_t y, float weight);

private:
  static uint64_t key(int32_t x, int32_t y)
  {
    return (static_cast<uint64_t>(static_cast<uint32_t>(x)) << 32) | static_cast<uint32_t>(y);
  }
  std::unordered_map<uint64_t, float> cells_;
};

// In-plane axes (u, v) and origin of the plane n.p + d = 0, the same for the same plane.
void planeBasis(const Eigen::Vector3d& normal, double d, Eigen::Vector3d& origin, Eigen::Vector3d& u,
                Eigen::Vector3d& v);

}  // namespace hough_plane_detector
