// Paper 3.4: peaks of a Hough space. From each seed cell a climb to the local maximum; a
// maximum over the whole peak window above the threshold is a peak; eq. 6 refines it to the
// window's weighted mean; eq. 7-10 merge peaks of nearly the same plane.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "hough_plane_detector/core/hough_parameterization.h"
#include "hough_plane_detector/core/sparse_hough_space.h"

namespace hough_plane_detector
{

struct HoughPeak
{
  Eigen::Vector3d hough = Eigen::Vector3d::Zero();  // refined (alpha, beta, d)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double d = 0.0;
  double value = 0.0;  // the space's value at the peak cell
};

class HoughPeakSearch
{
public:
  // peak_radius: half the peak window in cells.
  HoughPeakSearch(const HoughParameterization& param, int peak_radius);

  // Peaks reached from the seeds, each once, at least `threshold` high.
  // A peak reached from a seed marked in `full_height` is judged by its height between the
  // cells (peakHeight), not by its cell's value. `seed_tops`, when given, receives the cell each
  // seed climbed to, in the seeds' order.
  std::vector<HoughPeak> extract(const SparseHoughSpace& space, const std::vector<Eigen::Vector3i>& seeds,
                                 double threshold, const std::vector<char>& full_height = {},
                                 std::vector<Eigen::Vector3i>* seed_tops = nullptr) const;
  // Climbs from a cell to the local maximum under the (value, -index) total order.
  Eigen::Vector3i climb(const SparseHoughSpace& space, Eigen::Vector3i cell) const;
  // True when no cell of the peak window beats the cell under that order.
  bool isWindowMaximum(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const;
  // Eq. 6: m(x) = sum h(p) p / sum h(p) over the peak window, in cell coordinates.
  Eigen::Vector3d subVoxelMean(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const;
  // Height of the peak between the cells: a parabola through the log values on each axis.
  double peakHeight(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const;

private:
  const HoughParameterization& param_;
  int radius_;
};

// Eq. 7-10, strongest first: a peak within merge_angle and merge_distance of a kept one is
// absorbed into it (value-weighted mean of normal and d), unless `kept_apart` says the two
// are different surfaces.
std::vector<HoughPeak> mergeSimilarPeaks(
    std::vector<HoughPeak> peaks, double merge_angle, double merge_distance, const HoughParameterization& param,
    const std::function<bool(const HoughPeak&, const HoughPeak&)>& kept_apart = nullptr);

}  // namespace hough_plane_detector
