#include "hough_plane_detector/core/hough_voting.h"

#include <algorithm>
#include <cmath>

#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{

HoughVoting::HoughVoting(const HoughParameterization& param, int blur_radius, double blur_sigma)
  : param_(param), radius_(blur_radius)
{
  setBlurSigma(blur_sigma);
}

void HoughVoting::setBlurSigma(double blur_sigma)
{
  // Precomputed once (paper 3.3.2); maximum 1, so a lone vote of weight w blurs to peak w.
  sigma_ = blur_sigma;
  kernel_.resize(2 * radius_ + 1);
  for (int i = -radius_; i <= radius_; ++i)
    kernel_[i + radius_] = static_cast<float>(std::exp(-0.5 * i * i / (sigma_ * sigma_)));
}

int HoughVoting::vote(const std::vector<WindowSample>& samples, float overlap, const SparseHoughSpace& bounds)
{
  votes_.clear();
  int out_of_range = 0;
  const uint64_t sy = bounds.sizeY(), sz = bounds.sizeZ();
  auto push = [&](const Eigen::Vector3d& hough, float weight) {
    const Eigen::Vector3i c = nearestCell(param_.toCell(hough));
    if (!bounds.inBounds(c.x(), c.y(), c.z()))
    {
      ++out_of_range;
      return;
    }
    votes_.emplace_back((static_cast<uint64_t>(c.x()) * sy + c.y()) * sz + c.z(), weight);
  };
  for (const WindowSample& sample : samples)
  {
    // The paper's one vote per point, with far fewer eigen solves.
    const float weight = static_cast<float>(sample.count) * overlap;
    const Eigen::Vector3d hough = param_.toHough(sample.normal, sample.d);
    push(hough, weight);
    Eigen::Vector3d mirrored;
    if (param_.mirror(hough, mirrored)) push(mirrored, weight);
  }
  std::sort(votes_.begin(), votes_.end(),
            [](const std::pair<uint64_t, float>& a, const std::pair<uint64_t, float>& b) { return a.first < b.first; });
  cache_.clear();
  for (size_t i = 0; i < votes_.size();)
  {
    const uint64_t key = votes_[i].first;
    float weight = 0.0f;
    for (; i < votes_.size() && votes_[i].first == key; ++i) weight += votes_[i].second;
    const int z = static_cast<int>(key % sz), y = static_cast<int>((key / sz) % sy), x = static_cast<int>(key / (sz * sy));
    cache_.emplace_back(Eigen::Vector3i(x, y, z), weight);
  }
  return out_of_range;
}

void HoughVoting::blur(SparseHoughSpace& local) const
{
  local.clear();
  const float* k = kernel_.data();
  for (const auto& entry : cache_)
    local.addSeparable(entry.first.x(), entry.first.y(), entry.first.z(), radius_, k, k, k, entry.second);
}

void HoughVoting::addGaussian(SparseHoughSpace& space, const Eigen::Vector3d& hough, float weight, float cap) const
{
  const Eigen::Vector3d c = param_.toCell(hough);
  const Eigen::Vector3i ci = nearestCell(c);
  const int r = radius_;
  const double inv = 1.0 / (2.0 * sigma_ * sigma_);
  float kernels[3][16];
  for (int axis = 0; axis < 3; ++axis)
  {
    const double frac = c(axis) - ci(axis);
    for (int i = -r; i <= r; ++i) kernels[axis][i + r] = static_cast<float>(std::exp(-(i - frac) * (i - frac) * inv));
  }
  space.addSeparable(ci.x(), ci.y(), ci.z(), r, kernels[0], kernels[1], kernels[2], weight, cap);
}

}  // namespace hough_plane_detector
