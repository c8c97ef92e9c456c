#include "hough_plane_detector/core/hough_peaks.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{

HoughPeakSearch::HoughPeakSearch(const HoughParameterization& param, int peak_radius)
  : param_(param), radius_(peak_radius)
{
}

Eigen::Vector3i HoughPeakSearch::climb(const SparseHoughSpace& space, Eigen::Vector3i cell) const
{
  const int64_t sy = space.sizeY(), sz = space.sizeZ();
  auto index = [&](const Eigen::Vector3i& c) { return (static_cast<int64_t>(c.x()) * sy + c.y()) * sz + c.z(); };
  float value = space.value(cell.x(), cell.y(), cell.z());
  for (int step = 0; step < 1000; ++step)
  {
    Eigen::Vector3i best = cell;
    float best_value = value;
    int64_t best_index = index(cell);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
        {
          const Eigen::Vector3i n(cell.x() + dx, cell.y() + dy, cell.z() + dz);
          if (!space.inBounds(n.x(), n.y(), n.z())) continue;
          const float v = space.value(n.x(), n.y(), n.z());
          const int64_t i = index(n);
          if (v > best_value || (v == best_value && i < best_index))
          {
            best = n;
            best_value = v;
            best_index = i;
          }
        }
    if (best == cell) break;
    cell = best;
    value = best_value;
  }
  return cell;
}

bool HoughPeakSearch::isWindowMaximum(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const
{
  const int64_t sy = space.sizeY(), sz = space.sizeZ();
  const float value = space.value(cell.x(), cell.y(), cell.z());
  const int64_t own = (static_cast<int64_t>(cell.x()) * sy + cell.y()) * sz + cell.z();
  const int r = radius_;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy)
      for (int dz = -r; dz <= r; ++dz)
      {
        const int x = cell.x() + dx, y = cell.y() + dy, z = cell.z() + dz;
        const float v = space.value(x, y, z);
        if (v > value) return false;
        if (v == value && v > 0.0f && (static_cast<int64_t>(x) * sy + y) * sz + z < own) return false;
      }
  return true;
}

Eigen::Vector3d HoughPeakSearch::subVoxelMean(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const
{
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double total = 0.0;
  const int r = radius_;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy)
      for (int dz = -r; dz <= r; ++dz)
      {
        const double v = space.value(cell.x() + dx, cell.y() + dy, cell.z() + dz);
        weighted += v * Eigen::Vector3d(dx, dy, dz);
        total += v;
      }
  return cell.cast<double>() + (total > 0.0 ? Eigen::Vector3d(weighted / total) : Eigen::Vector3d::Zero());
}

double HoughPeakSearch::peakHeight(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const
{
  // A Gaussian's logarithm is a parabola along each axis: three samples give its height at the
  // vertex wherever between cells the plane fell (a lone vote of weight w half a cell off on all
  // three axes reads 0.69 w at its nearest cell).
  const double centre = space.value(cell.x(), cell.y(), cell.z());
  if (!(centre > 0.0)) return centre;
  const double log_centre = std::log(centre);
  double log_height = log_centre;
  for (int axis = 0; axis < 3; ++axis)
  {
    Eigen::Vector3i below = cell, above = cell;
    --below(axis);
    ++above(axis);
    const double l = space.value(below.x(), below.y(), below.z()), r = space.value(above.x(), above.y(), above.z());
    if (!(l > 0.0 && r > 0.0)) continue;
    const double log_l = std::log(l), log_r = std::log(r), curvature = log_l - 2.0 * log_centre + log_r;
    if (!(curvature < 0.0)) continue;  // a plateau (capped cells): the cell is the height
    log_height -= (log_l - log_r) * (log_l - log_r) / (8.0 * curvature);
  }
  return std::exp(log_height);
}

std::vector<HoughPeak> HoughPeakSearch::extract(const SparseHoughSpace& space, const std::vector<Eigen::Vector3i>& seeds,
                                                double threshold, const std::vector<char>& full_height,
                                                std::vector<Eigen::Vector3i>* seed_tops) const
{
  if (seed_tops) seed_tops->clear();
  std::vector<HoughPeak> peaks;
  std::unordered_set<int64_t> visited;
  const int64_t sy = space.sizeY(), sz = space.sizeZ();
  for (size_t i = 0; i < seeds.size(); ++i)
  {
    const Eigen::Vector3i top = climb(space, seeds[i]);
    if (seed_tops) seed_tops->push_back(top);
    if (!visited.insert((static_cast<int64_t>(top.x()) * sy + top.y()) * sz + top.z()).second) continue;
    const float value = space.value(top.x(), top.y(), top.z());
    const bool by_height = i < full_height.size() && full_height[i];
    if ((by_height ? peakHeight(space, top) : value) < threshold || !isWindowMaximum(space, top)) continue;
    HoughPeak peak;
    peak.hough = param_.fromCell(subVoxelMean(space, top));
    // Mirrored twins beyond the border are the same plane. A peak right on the border may
    // refine to a hair beyond it on both sides, so allow a cell; the merge joins the twins.
    if (peak.hough.head<2>().norm() > M_PI / 2 + param_.angleStep()) continue;
    param_.fromHough(peak.hough, peak.normal, peak.d);
    peak.value = value;
    peaks.push_back(peak);
  }
  return peaks;
}

std::vector<HoughPeak> mergeSimilarPeaks(std::vector<HoughPeak> peaks, double merge_angle, double merge_distance,
                                         const HoughParameterization& param,
                                         const std::function<bool(const HoughPeak&, const HoughPeak&)>& kept_apart)
{
  std::sort(peaks.begin(), peaks.end(), [](const HoughPeak& a, const HoughPeak& b) { return a.value > b.value; });
  std::vector<HoughPeak> merged;
  std::vector<double> weights;
  for (const HoughPeak& peak : peaks)
  {
    bool absorbed = false;
    for (size_t i = 0; i < merged.size() && !absorbed; ++i)
    {
      HoughPeak& m = merged[i];
      const double sign = m.normal.dot(peak.normal) >= 0.0 ? 1.0 : -1.0;
      const Eigen::Vector3d n2 = sign * peak.normal;
      const double d2 = sign * peak.d;
      // Eq. 7-8: similar when both the normal angle and the d difference are small.
      if (unsignedAngle(m.normal, n2) > merge_angle || std::abs(m.d - d2) > merge_distance) continue;
      if (kept_apart && kept_apart(m, peak)) continue;
      // Eq. 9-10: strength-weighted mean of normal and d.
      const double w1 = weights[i], w2 = peak.value;
      m.normal = ((w1 * m.normal + w2 * n2) / (w1 + w2)).normalized();
      m.d = (w1 * m.d + w2 * d2) / (w1 + w2);
      weights[i] = w1 + w2;
      absorbed = true;
    }
    if (!absorbed)
    {
      merged.push_back(peak);
      weights.push_back(peak.value);
    }
  }
  for (HoughPeak& m : merged) m.hough = param.toHough(m.normal, m.d);
  return merged;
}

}  // namespace hough_plane_detector
