// Paper 3.3: each planar window votes once into the per-frame cache space (one entry per
// distinct cell, 3.3.3), which is blurred by a separable Gaussian into the local space (3.3.2).
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "hough_plane_detector/core/hough_parameterization.h"
#include "hough_plane_detector/core/normal_estimator.h"
#include "hough_plane_detector/core/sparse_hough_space.h"

namespace hough_plane_detector
{

class HoughVoting
{
public:
  // blur_radius: half the kernel size in cells; blur_sigma in cells.
  HoughVoting(const HoughParameterization& param, int blur_radius, double blur_sigma);
  void setBlurSigma(double blur_sigma);

  // One vote per window, weighted by its points times `overlap` (stride^2 / window^2), so the
  // space counts points; windows near the chart border vote for their mirror too. Returns
  // the votes that fell outside the space (planes beyond max_distance).
  int vote(const std::vector<WindowSample>& samples, float overlap, const SparseHoughSpace& bounds);
  // Distinct voted cells of the last vote() and their summed weights.
  const std::vector<std::pair<Eigen::Vector3i, float>>& cache() const { return cache_; }
  // The cache blurred into `local` (cleared first).
  void blur(SparseHoughSpace& local) const;
  // One Gaussian of maximum `weight` centred on continuous Hough coordinates (the global
  // space keeps the sub-voxel position eq. 6 refined), cells capped at `cap`.
  void addGaussian(SparseHoughSpace& space, const Eigen::Vector3d& hough, float weight, float cap) const;
  int blurRadius() const { return radius_; }

private:
  const HoughParameterization& param_;
  int radius_;
  double sigma_;
  std::vector<float> kernel_;
  std::vector<std::pair<uint64_t, float>> votes_;
  std::vector<std::pair<Eigen::Vector3i, float>> cache_;
};

}  // namespace hough_plane_detector
