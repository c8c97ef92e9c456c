#include "hough_plane_detector/core/plane_extent.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace hough_plane_detector
{

PlaneBasis::PlaneBasis(const Eigen::Vector3d& normal, double d)
{
  // u from the world axis least aligned with the normal.
  Eigen::Index axis;
  normal.cwiseAbs().minCoeff(&axis);
  u = normal.cross(Eigen::Vector3d::Unit(axis)).normalized();
  v = normal.cross(u);
  origin = -d * normal;
}

Eigen::Vector2d PlaneBasis::project(const Eigen::Vector3d& point) const
{
  const Eigen::Vector3d q = point - origin;
  return Eigen::Vector2d(q.dot(u), q.dot(v));
}

void PlaneExtent::add(const Eigen::Vector3d& world_point, const Eigen::Vector3d& normal, double d, int64_t frame,
                      float fade)
{
  if (!basis_) basis_ = std::make_shared<const PlaneBasis>(normal, d);
  const Eigen::Vector2d point = basis_->project(world_point);
  const int32_t x = static_cast<int32_t>(std::floor(point.x() / kCellSize));
  const int32_t y = static_cast<int32_t>(std::floor(point.y() / kCellSize));
  if (cells_.size() >= kMaxCells && cells_.find(key(x, y)) == cells_.end()) return;  // bounded memory
  const auto inserted = cells_.try_emplace(key(x, y), Cell{1.0f, frame});
  if (inserted.second) return;
  const auto it = inserted.first;
  // Fading is applied lazily: a cell's weight is brought up to date when it is touched.
  it->second.weight = std::min(kMaxWeight, std::max(0.0f, weightAt(it->second, frame, fade)) + 1.0f);
  it->second.seen = frame;
}

void PlaneExtent::sweep(int64_t frame, float fade)
{
  for (auto it = cells_.begin(); it != cells_.end();)
  {
    if (weightAt(it->second, frame, fade) <= 0.0f)
      it = cells_.erase(it);
    else
      ++it;
  }
}

std::vector<Eigen::Vector3d> PlaneExtent::hull(int64_t frame, float fade) const
{
  std::vector<std::pair<int32_t, int32_t>> live;
  for (const auto& cell : cells_)
    if (weightAt(cell.second, frame, fade) > 0.0f)
      live.emplace_back(static_cast<int32_t>(cell.first >> 32), static_cast<int32_t>(cell.first & 0xffffffffu));
  return hullOf(live);
}

std::vector<std::vector<Eigen::Vector3d>> PlaneExtent::regions(int64_t frame, float fade) const
{
  // Live cells within kRegionGap cells of each other are one region: far blocks mark cells a
  // few centimetres apart, while two tables or two rooms' floors lie metres apart.
  constexpr int32_t kRegionGap = 2;
  constexpr size_t kMinRegionCells = 4;
  std::unordered_map<uint64_t, int> label;  // live cell -> region (-1: not yet visited)
  for (const auto& cell : cells_)
    if (weightAt(cell.second, frame, fade) > 0.0f) label.emplace(cell.first, -1);
  std::vector<std::vector<Eigen::Vector3d>> out;
  std::vector<std::pair<int32_t, int32_t>> region, queue;
  int next = 0;
  for (auto& seed : label)
  {
    if (seed.second >= 0) continue;
    seed.second = next;
    queue.assign(1, {static_cast<int32_t>(seed.first >> 32), static_cast<int32_t>(seed.first & 0xffffffffu)});
    region.clear();
    while (!queue.empty())
    {
      const auto c = queue.back();
      queue.pop_back();
      region.push_back(c);
      for (int32_t dx = -kRegionGap; dx <= kRegionGap; ++dx)
        for (int32_t dy = -kRegionGap; dy <= kRegionGap; ++dy)
        {
          const auto it = label.find(key(c.first + dx, c.second + dy));
          if (it == label.end() || it->second >= 0) continue;
          it->second = next;
          queue.emplace_back(c.first + dx, c.second + dy);
        }
    }
    ++next;
    if (region.size() >= kMinRegionCells) out.push_back(hullOf(region));
  }
  // Largest first, so that the order does not depend on the hash map's.
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return a.size() != b.size() ? a.size() > b.size() : a.front().x() < b.front().x();
  });
  return out;
}

std::vector<Eigen::Vector3d> PlaneExtent::hullOf(const std::vector<std::pair<int32_t, int32_t>>& live) const
{
  if (!basis_) return {};
  // Only the outermost live cell of each row can be on the hull.
  std::map<int32_t, std::pair<int32_t, int32_t>> rows;
  for (const auto& [x, y] : live)
  {
    auto it = rows.find(y);
    if (it == rows.end())
      rows.emplace(y, std::make_pair(x, x));
    else
      it->second = {std::min(it->second.first, x), std::max(it->second.second, x)};
  }
  std::vector<Eigen::Vector2d> corners;
  for (const auto& row : rows)
  {
    const double y = row.first * kCellSize;
    const double x0 = row.second.first * kCellSize, x1 = (row.second.second + 1) * kCellSize;
    corners.insert(corners.end(), {{x0, y}, {x0, y + kCellSize}, {x1, y}, {x1, y + kCellSize}});
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
  for (const auto& c : chain) polygon.push_back(basis_->lift(c));
  return polygon;
}

std::vector<std::pair<std::pair<int32_t, int32_t>, PlaneExtent::Cell>> PlaneExtent::cells() const
{
  std::vector<std::pair<std::pair<int32_t, int32_t>, Cell>> out;
  for (const auto& cell : cells_)
    out.push_back({{static_cast<int32_t>(cell.first >> 32), static_cast<int32_t>(cell.first & 0xffffffffu)}, cell.second});
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

void PlaneExtent::setCell(int32_t x, int32_t y, const Cell& cell)
{
  cells_[key(x, y)] = cell;
}

}  // namespace hough_plane_detector
