#include "hough_plane_detector/core/plane_extent.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <climits>
#include <cstdint>

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
  const uint64_t k = key(x, y);
  // Neighbouring blocks mostly fall in the cell before: no hash look-up for them.
  if (last_added_ >= cells_.size() || cells_[last_added_].first != k)
  {
    const auto found = index_.find(k);
    if (found == index_.end())
    {
      if (cells_.size() >= kMaxCells) return;  // bounded memory
      last_added_ = cells_.size();
      appendCell(k, Cell{1.0f, frame});
      return;
    }
    last_added_ = found->second;
  }
  Cell& cell = cells_[last_added_].second;
  // Fading is applied lazily: a cell's weight is brought up to date when it is touched.
  cell.weight = std::min(kMaxWeight, std::max(0.0f, weightAt(cell, frame, fade)) + 1.0f);
  cell.seen = frame;
}

void PlaneExtent::sweep(int64_t frame, float fade)
{
  // Compacted in order; the cells that moved take their new positions in the index.
  size_t kept = 0;
  for (size_t i = 0; i < cells_.size(); ++i)
  {
    if (weightAt(cells_[i].second, frame, fade) <= 0.0f)
    {
      index_.erase(cells_[i].first);
      continue;
    }
    if (kept != i)
    {
      cells_[kept] = cells_[i];
      index_[cells_[kept].first] = static_cast<uint32_t>(kept);
    }
    ++kept;
  }
  cells_.resize(kept);
}

std::vector<Eigen::Vector3d> PlaneExtent::hull(int64_t frame, float fade) const
{
  std::vector<std::pair<int32_t, int32_t>> live;
  for (const auto& cell : cells_)
    if (weightAt(cell.second, frame, fade) > 0.0f)
      live.emplace_back(static_cast<int32_t>(cell.first >> 32), static_cast<int32_t>(cell.first & 0xffffffffu));
  return hullOf(live);
}

std::vector<std::vector<std::pair<int32_t, int32_t>>> PlaneExtent::connectedRegions(int64_t frame, float fade) const
{
  // Live cells within kRegionGap cells of each other are one region: far blocks mark cells a
  // few centimetres apart, while two tables or two rooms' floors lie metres apart.
  constexpr int32_t kRegionGap = 2;
  constexpr size_t kMinRegionCells = 4;
  constexpr int64_t kMaxDenseCells = 1 << 20;  // a dense label grid up to 50 m x 50 m of plane
  std::vector<std::pair<int32_t, int32_t>> live;
  int32_t x_min = INT32_MAX, y_min = INT32_MAX, x_max = INT32_MIN, y_max = INT32_MIN;
  for (const auto& cell : cells_)
    if (weightAt(cell.second, frame, fade) > 0.0f)
    {
      const int32_t x = static_cast<int32_t>(cell.first >> 32), y = static_cast<int32_t>(cell.first & 0xffffffffu);
      live.emplace_back(x, y);
      x_min = std::min(x_min, x), x_max = std::max(x_max, x), y_min = std::min(y_min, y), y_max = std::max(y_max, y);
    }
  std::vector<std::vector<std::pair<int32_t, int32_t>>> out;
  if (live.empty()) return out;
  std::sort(live.begin(), live.end());  // regions independent of the hash map's order
  const int64_t w = int64_t(x_max) - x_min + 1, h = int64_t(y_max) - y_min + 1;
  // label[i] of live[i]; a dense index of the live cells when the extent is compact.
  std::vector<int> label(live.size(), -1);
  std::vector<int32_t> dense;
  std::unordered_map<uint64_t, int32_t> sparse;
  const bool use_dense = w * h <= kMaxDenseCells;
  if (use_dense)
  {
    dense.assign(static_cast<size_t>(w * h), -1);
    for (size_t i = 0; i < live.size(); ++i)
      dense[static_cast<size_t>((live[i].second - y_min) * w + (live[i].first - x_min))] = static_cast<int32_t>(i);
  }
  else
    for (size_t i = 0; i < live.size(); ++i) sparse.emplace(key(live[i].first, live[i].second), static_cast<int32_t>(i));
  auto find = [&](int32_t x, int32_t y) -> int32_t {
    if (use_dense)
    {
      if (x < x_min || x > x_max || y < y_min || y > y_max) return -1;
      return dense[static_cast<size_t>((int64_t(y) - y_min) * w + (int64_t(x) - x_min))];
    }
    const auto it = sparse.find(key(x, y));
    return it == sparse.end() ? -1 : it->second;
  };
  std::vector<int32_t> queue;
  int next = 0;
  for (size_t seed = 0; seed < live.size(); ++seed)
  {
    if (label[seed] >= 0) continue;
    label[seed] = next;
    queue.assign(1, static_cast<int32_t>(seed));
    std::vector<std::pair<int32_t, int32_t>> region;
    while (!queue.empty())
    {
      const auto c = live[queue.back()];
      queue.pop_back();
      region.push_back(c);
      for (int32_t dx = -kRegionGap; dx <= kRegionGap; ++dx)
        for (int32_t dy = -kRegionGap; dy <= kRegionGap; ++dy)
        {
          const int32_t j = find(c.first + dx, c.second + dy);
          if (j < 0 || label[j] >= 0) continue;
          label[j] = next;
          queue.push_back(j);
        }
    }
    ++next;
    if (region.size() >= kMinRegionCells) out.push_back(std::move(region));
  }
  return out;
}

std::vector<std::vector<Eigen::Vector3d>> PlaneExtent::regions(int64_t frame, float fade) const
{
  std::vector<std::vector<Eigen::Vector3d>> out;
  for (const auto& region : connectedRegions(frame, fade)) out.push_back(hullOf(region));
  // Largest first, so that the order does not depend on the hash map's.
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return a.size() != b.size() ? a.size() > b.size() : a.front().x() < b.front().x();
  });
  return out;
}

std::vector<PlaneOutline> PlaneExtent::outlines(int64_t frame, float fade) const
{
  std::vector<PlaneOutline> out;
  for (const auto& region : connectedRegions(frame, fade))
  {
    const std::vector<Eigen::Vector3d> hull = hullOf(region);
    for (PlaneOutline& outline : outlinesOf(region))
    {
      outline.hull = hull;
      out.push_back(std::move(outline));
    }
  }
  std::sort(out.begin(), out.end(), [](const PlaneOutline& a, const PlaneOutline& b) { return a.area > b.area; });
  return out;
}

namespace
{
// A region's cells on a coarser grid (kShapeCoarse x kShapeCoarse cells), closed (dilate, then
// erode, 3 x 3): far blocks mark cells a few centimetres apart, which the regions bridge and the
// shape must not show as a lattice of holes; holes and concave corners of 10 cm and more remain.
constexpr int32_t kShapeCoarse = 2;
constexpr double kShapeCell = kShapeCoarse * PlaneExtent::kCellSize;

struct ShapeGrid
{
  int32_t x0 = 0, y0 = 0, w = 0, h = 0;  // coarse cell (x0, y0) at index 0; w x h cells
  std::vector<uint8_t> closed;
  size_t at(int32_t x, int32_t y) const { return static_cast<size_t>(y) * w + x; }
  bool in(int32_t x, int32_t y) const { return x >= 0 && y >= 0 && x < w && y < h && closed[at(x, y)]; }
  Eigen::Vector2d corner(int32_t x, int32_t y) const { return Eigen::Vector2d((x + x0) * kShapeCell, (y + y0) * kShapeCell); }
};

ShapeGrid closedShapeGrid(const std::vector<std::pair<int32_t, int32_t>>& region)
{
  auto coarse = [](int32_t v) { return v >= 0 ? v / kShapeCoarse : -((-v + kShapeCoarse - 1) / kShapeCoarse); };
  int32_t x_min = INT32_MAX, y_min = INT32_MAX, x_max = INT32_MIN, y_max = INT32_MIN;
  for (const auto& c : region)
  {
    x_min = std::min(x_min, coarse(c.first)), x_max = std::max(x_max, coarse(c.first));
    y_min = std::min(y_min, coarse(c.second)), y_max = std::max(y_max, coarse(c.second));
  }
  // A dense grid over the region with a margin of 2: dilation reaches 1 beyond, the boundary 1 more.
  ShapeGrid grid;
  grid.x0 = x_min - 2, grid.y0 = y_min - 2, grid.w = x_max - x_min + 5, grid.h = y_max - y_min + 5;
  const int32_t w = grid.w, h = grid.h;
  std::vector<uint8_t> marked(static_cast<size_t>(w) * h, 0), dilated(marked.size(), 0);
  grid.closed.assign(marked.size(), 0);
  for (const auto& c : region) marked[grid.at(coarse(c.first) - grid.x0, coarse(c.second) - grid.y0)] = 1;
  for (int32_t y = 1; y + 1 < h; ++y)
    for (int32_t x = 1; x + 1 < w; ++x)
      if (marked[grid.at(x, y)])
        for (int32_t dy = -1; dy <= 1; ++dy)
          for (int32_t dx = -1; dx <= 1; ++dx) dilated[grid.at(x + dx, y + dy)] = 1;
  for (int32_t y = 1; y + 1 < h; ++y)
    for (int32_t x = 1; x + 1 < w; ++x)
    {
      bool inside = true;
      for (int32_t dy = -1; dy <= 1 && inside; ++dy)
        for (int32_t dx = -1; dx <= 1 && inside; ++dx) inside = dilated[grid.at(x + dx, y + dy)] != 0;
      grid.closed[grid.at(x, y)] = inside || marked[grid.at(x, y)];
    }
  return grid;
}

double signedArea(const std::vector<Eigen::Vector2d>& polygon)
{
  double area = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i)
  {
    const Eigen::Vector2d& p = polygon[i];
    const Eigen::Vector2d& q = polygon[(i + 1) % polygon.size()];
    area += 0.5 * (p.x() * q.y() - q.x() * p.y());
  }
  return area;
}

// Even-odd test.
bool polygonContains(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& q)
{
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++)
    if ((polygon[i].y() > q.y()) != (polygon[j].y() > q.y()) &&
        q.x() < (polygon[j].x() - polygon[i].x()) * (q.y() - polygon[i].y()) / (polygon[j].y() - polygon[i].y()) + polygon[i].x())
      inside = !inside;
  return inside;
}

// The closed grid's boundary loops (corners only): outer boundaries counter-clockwise (positive
// area), holes clockwise.
void traceBoundaries(const ShapeGrid& grid, std::vector<std::vector<Eigen::Vector2d>>& outers,
                     std::vector<std::vector<Eigen::Vector2d>>& holes)
{
  // Boundary edges with the region on their left (counter-clockwise around each cell), at most
  // two leaving any grid vertex.
  const int32_t vw = grid.w + 1;
  std::vector<std::array<int32_t, 2>> out_edges(static_cast<size_t>(vw) * (grid.h + 1), {-1, -1});
  size_t edge_count = 0;
  auto addEdge = [&](int32_t fx, int32_t fy, int32_t tx, int32_t ty) {
    auto& slots = out_edges[static_cast<size_t>(fy) * vw + fx];
    slots[slots[0] < 0 ? 0 : 1] = ty * vw + tx;
    ++edge_count;
  };
  for (int32_t y = 0; y < grid.h; ++y)
    for (int32_t x = 0; x < grid.w; ++x)
    {
      if (!grid.closed[grid.at(x, y)]) continue;
      if (!grid.in(x, y - 1)) addEdge(x, y, x + 1, y);
      if (!grid.in(x + 1, y)) addEdge(x + 1, y, x + 1, y + 1);
      if (!grid.in(x, y + 1)) addEdge(x + 1, y + 1, x, y + 1);
      if (!grid.in(x - 1, y)) addEdge(x, y + 1, x, y);
    }
  auto point = [&](int32_t v) { return grid.corner(v % vw, v / vw); };
  for (size_t start = 0; start < out_edges.size() && edge_count > 0; ++start)
    while (out_edges[start][0] >= 0)
    {
      std::vector<int32_t> loop;
      int32_t v = static_cast<int32_t>(start), previous = -1;
      do
      {
        auto& slots = out_edges[v];
        int chosen = slots[0] >= 0 ? 0 : 1;
        // Where two loops touch at a corner, keep to the left turn: each loop stays simple.
        if (slots[0] >= 0 && slots[1] >= 0 && previous >= 0)
        {
          const int32_t dx = v % vw - previous % vw, dy = v / vw - previous / vw;
          const int32_t ex = slots[1] % vw - v % vw, ey = slots[1] / vw - v / vw;
          if (dx * ey - dy * ex > 0) chosen = 1;
        }
        loop.push_back(v);
        previous = v;
        const int32_t next = slots[chosen];
        slots[chosen] = -1;
        if (chosen == 0) std::swap(slots[0], slots[1]);  // keep a remaining edge in slot 0
        --edge_count;
        v = next;
      } while (v != static_cast<int32_t>(start) && (out_edges[v][0] >= 0 || out_edges[v][1] >= 0));
      // Corners only: drop vertices between collinear edges.
      std::vector<Eigen::Vector2d> polygon;
      for (size_t i = 0; i < loop.size(); ++i)
      {
        const Eigen::Vector2d p = point(loop[(i + loop.size() - 1) % loop.size()]), c = point(loop[i]),
                              n = point(loop[(i + 1) % loop.size()]);
        const Eigen::Vector2d d1 = c - p, d2 = n - c;
        if (std::abs(d1.x() * d2.y() - d1.y() * d2.x()) < 1e-12) continue;
        polygon.push_back(c);
      }
      if (polygon.size() < 3) continue;
      (signedArea(polygon) > 0.0 ? outers : holes).push_back(polygon);
    }
}
}  // namespace

std::vector<PlaneOutline> PlaneExtent::outlinesOf(const std::vector<std::pair<int32_t, int32_t>>& region) const
{
  if (!basis_ || region.empty()) return {};
  const ShapeGrid grid = closedShapeGrid(region);
  std::vector<std::vector<Eigen::Vector2d>> outers, holes;
  traceBoundaries(grid, outers, holes);
  auto lift = [this](const std::vector<Eigen::Vector2d>& polygon) {
    std::vector<Eigen::Vector3d> lifted;
    for (const Eigen::Vector2d& q : polygon) lifted.push_back(basis_->lift(q));
    return lifted;
  };
  std::vector<PlaneOutline> shapes(outers.size());
  for (size_t o = 0; o < outers.size(); ++o)
  {
    shapes[o].boundary = lift(outers[o]);
    shapes[o].area = signedArea(outers[o]);
  }
  // Each hole belongs to the outer boundary around a point just right of its first edge (inside
  // the hole, which is on the right of a clockwise loop); its (negative) area is taken off.
  for (const auto& hole : holes)
  {
    const Eigen::Vector2d edge = hole[1] - hole[0];
    const Eigen::Vector2d q = 0.5 * (hole[0] + hole[1]) + 0.25 * kShapeCell * Eigen::Vector2d(edge.y(), -edge.x()).normalized();
    for (size_t o = 0; o < outers.size(); ++o)
      if (polygonContains(outers[o], q))
      {
        shapes[o].holes.push_back(lift(hole));
        shapes[o].area += signedArea(hole);
        break;
      }
  }
  // Rows of the closed grid as rectangles, each given to the outer boundary around it.
  for (int32_t y = 0; y < grid.h; ++y)
    for (int32_t x = 0; x < grid.w;)
    {
      if (!grid.closed[grid.at(x, y)])
      {
        ++x;
        continue;
      }
      int32_t end = x;
      while (end + 1 < grid.w && grid.closed[grid.at(end + 1, y)]) ++end;
      const Eigen::Vector2d a = grid.corner(x, y), b = grid.corner(end + 1, y + 1);
      for (size_t o = 0; o < outers.size(); ++o)
        if (polygonContains(outers[o], 0.5 * (a + b)))
        {
          shapes[o].fill.push_back({basis_->lift(a), basis_->lift({b.x(), a.y()}), basis_->lift(b), basis_->lift({a.x(), b.y()})});
          break;
        }
      x = end + 1;
    }
  return shapes;
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
  const uint64_t k = key(x, y);
  const auto found = index_.find(k);
  if (found == index_.end())
    appendCell(k, cell);
  else
    cells_[found->second].second = cell;
}

void PlaneExtent::appendCell(uint64_t k, const Cell& cell)
{
  index_.emplace(k, static_cast<uint32_t>(cells_.size()));
  cells_.emplace_back(k, cell);
}

}  // namespace hough_plane_detector
