#include "hough_plane_detector/core/plane_extent.h"

#include <algorithm>
#include <cmath>

namespace hough_plane_detector
{

void planeBasis(const Eigen::Vector3d& normal, double d, Eigen::Vector3d& origin, Eigen::Vector3d& u,
                Eigen::Vector3d& v)
{
  // The world axis least aligned with the normal fixes u, so the basis does not spin with
  // small changes of the normal.
  Eigen::Index axis;
  normal.cwiseAbs().minCoeff(&axis);
  u = normal.cross(Eigen::Vector3d::Unit(axis)).normalized();
  v = normal.cross(u);
  origin = -d * normal;
}

void PlaneExtent::add(const Eigen::Vector3d& normal, double d, const Eigen::Vector3d& point)
{
  Eigen::Vector3d origin, u, v;
  planeBasis(normal, d, origin, u, v);
  const Eigen::Vector3d q = point - origin;
  const int32_t x = static_cast<int32_t>(std::floor(q.dot(u) / kCellSize));
  const int32_t y = static_cast<int32_t>(std::floor(q.dot(v) / kCellSize));
  auto it = cells_.find(key(x, y));
  if (it == cells_.end())
  {
    if (cells_.size() >= kMaxCells) return;  // bounded memory
    cells_.emplace(key(x, y), 1.0f);
  }
  else
  {
    it->second = std::min(kMaxWeight, it->second + 1.0f);
  }
}

void PlaneExtent::decay(float amount)
{
  for (auto it = cells_.begin(); it != cells_.end();)
  {
    it->second -= amount;
    if (it->second <= 0.0f)
      it = cells_.erase(it);
    else
      ++it;
  }
}

std::vector<Eigen::Vector3d> PlaneExtent::hull(const Eigen::Vector3d& normal, double d) const
{
  std::vector<Eigen::Vector2d> corners;
  corners.reserve(cells_.size() * 4);
  for (const auto& cell : cells_)
  {
    const double x = static_cast<int32_t>(cell.first >> 32) * kCellSize;
    const double y = static_cast<int32_t>(cell.first & 0xffffffffu) * kCellSize;
    corners.emplace_back(x, y);
    corners.emplace_back(x + kCellSize, y);
    corners.emplace_back(x, y + kCellSize);
    corners.emplace_back(x + kCellSize, y + kCellSize);
  }
  std::vector<Eigen::Vector3d> polygon;
  if (corners.size() < 3) return polygon;
  // Andrew's monotone chain.
  std::sort(corners.begin(), corners.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> chain(2 * corners.size());
  size_t k = 0;
  for (size_t i = 0; i < corners.size(); ++i)
  {
    while (k >= 2 && cross(chain[k - 2], chain[k - 1], corners[i]) <= 0) --k;
    chain[k++] = corners[i];
  }
  for (size_t i = corners.size() - 1, lower = k + 1; i > 0; --i)
  {
    while (k >= lower && cross(chain[k - 2], chain[k - 1], corners[i - 1]) <= 0) --k;
    chain[k++] = corners[i - 1];
  }
  chain.resize(k - 1);
  Eigen::Vector3d origin, u, v;
  planeBasis(normal, d, origin, u, v);
  for (const auto& c : chain) polygon.push_back(origin + c.x() * u + c.y() * v);
  return polygon;
}

std::vector<std::pair<std::pair<int32_t, int32_t>, float>> PlaneExtent::cells() const
{
  std::vector<std::pair<std::pair<int32_t, int32_t>, float>> out;
  for (const auto& cell : cells_)
    out.push_back({{static_cast<int32_t>(cell.first >> 32), static_cast<int32_t>(cell.first & 0xffffffffu)}, cell.second});
  std::sort(out.begin(), out.end());
  return out;
}

void PlaneExtent::setCell(int32_t x, int32_t y, float weight)
{
  cells_[key(x, y)] = weight;
}

}  // namespace hough_plane_detector
