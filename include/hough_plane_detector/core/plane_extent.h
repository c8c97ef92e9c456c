// Where on its infinite plane a plane was seen: 5 cm cells in the plane's own 2-D coordinates,
// accumulated over frames with bounded memory, fading like the Hough space, and their convex
// hull as the polygon markers and messages show.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace hough_plane_detector
{

// In-plane axes (u, v) and origin of the plane n.p + d = 0, the same for the same plane.
struct PlaneBasis
{
  PlaneBasis(const Eigen::Vector3d& normal, double d);
  PlaneBasis(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v)
    : origin(origin), u(u), v(v)
  {
  }
  Eigen::Vector2d project(const Eigen::Vector3d& point) const;
  Eigen::Vector3d lift(const Eigen::Vector2d& q) const { return origin + q.x() * u + q.y() * v; }
  Eigen::Vector3d origin, u, v;
};

// The shape of one connected region of a plane's extent, world frame: its outline, concave
// where the region is, counter-clockwise about the plane's normal, and its holes (where a
// pillar stands), clockwise; `fill` covers the region with rectangles (4 corners each), rows
// of cells merged, for filled markers.
struct PlaneOutline
{
  std::vector<Eigen::Vector3d> hull;  // convex hull of its region (as regions() gives it)
  std::vector<Eigen::Vector3d> boundary;
  std::vector<std::vector<Eigen::Vector3d>> holes;
  std::vector<std::array<Eigen::Vector3d, 4>> fill;
  double area = 0.0;  // m^2, holes excluded
};

class PlaneExtent
{
public:
  static constexpr double kCellSize = 0.05;     // m
  static constexpr size_t kMaxCells = 40000;    // 100 m^2 of plane
  static constexpr float kMaxWeight = 20.0f;

  // Marks the cell under a world point of the plane (normal, d) at frame `frame`. The first
  // call fixes the extent's own 2-D basis: a basis recomputed from each new estimate of the
  // normal could turn, and the cells with it.
  void add(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double d, int64_t frame, float fade_per_frame);
  // Drops cells that have faded out by `frame` (every cell loses fade_per_frame per frame
  // since it was last seen), so the extent shrinks as a plane fades.
  void sweep(int64_t frame, float fade_per_frame);
  // Convex hull of the live cells, counter-clockwise about the normal, in the world frame.
  std::vector<Eigen::Vector3d> hull(int64_t frame, float fade_per_frame) const;
  // One convex hull per connected region of live cells (cells up to 10 cm apart connect;
  // regions of fewer than 4 cells are left out), largest first: two tables at one height, or
  // two rooms' floors, are two regions of one plane.
  std::vector<std::vector<Eigen::Vector3d>> regions(int64_t frame, float fade_per_frame) const;
  // The regions' shapes (the same regions) on a 10 cm grid, gaps of one grid cell closed,
  // largest first.
  std::vector<PlaneOutline> outlines(int64_t frame, float fade_per_frame) const;
  size_t cellCount() const { return cells_.size(); }
  // Calls f(centre) with the world-frame centre of every live cell (unordered) whose
  // coordinates are multiples of `every` (2: a 10 cm lattice).
  template <class F>
  void forEachLiveCell(int64_t frame, float fade_per_frame, int every, F f) const
  {
    if (!basis_) return;
    for (const auto& cell : cells_)  // a plain array: no hash-bucket chasing (the evidence check's cost)
    {
      const int32_t x = static_cast<int32_t>(cell.first >> 32), y = static_cast<int32_t>(cell.first & 0xffffffffu);
      if (x % every != 0 || y % every != 0) continue;
      if (weightAt(cell.second, frame, fade_per_frame) <= 0.0f) continue;
      f(basis_->lift(Eigen::Vector2d((x + 0.5) * kCellSize, (y + 0.5) * kCellSize)));
    }
  }

  struct Cell
  {
    float weight;       // as of frame `seen`
    int64_t seen;
  };
  // For saving maps: cells as ((x, y), cell).
  std::vector<std::pair<std::pair<int32_t, int32_t>, Cell>> cells() const;
  void setCell(int32_t x, int32_t y, const Cell& cell);
  const PlaneBasis* basis() const { return basis_.get(); }
  void setBasis(const PlaneBasis& basis) { basis_.reset(new PlaneBasis(basis)); }

private:
  static uint64_t key(int32_t x, int32_t y)
  {
    return (static_cast<uint64_t>(static_cast<uint32_t>(x)) << 32) | static_cast<uint32_t>(y);
  }
  static float weightAt(const Cell& c, int64_t frame, float fade) { return c.weight - fade * (frame - c.seen); }
  std::vector<Eigen::Vector3d> hullOf(const std::vector<std::pair<int32_t, int32_t>>& cells) const;
  // Live cells grouped into connected regions (cells up to kRegionGap apart), each of at least
  // kMinRegionCells cells.
  std::vector<std::vector<std::pair<int32_t, int32_t>>> connectedRegions(int64_t frame, float fade) const;
  std::vector<PlaneOutline> outlinesOf(const std::vector<std::pair<int32_t, int32_t>>& region) const;
  // A new cell at the end of the array, and its position in the index.
  void appendCell(uint64_t k, const Cell& cell);
  // The cells as (key, cell) in one array, which every pass over the extent walks in order, and
  // each key's position in it for the per-block look-up of add().
  std::vector<std::pair<uint64_t, Cell>> cells_;
  std::unordered_map<uint64_t, uint32_t> index_;
  size_t last_added_ = 0;  // position of the cell add() marked last (checked against its key)
  std::shared_ptr<const PlaneBasis> basis_;
};

}  // namespace hough_plane_detector
