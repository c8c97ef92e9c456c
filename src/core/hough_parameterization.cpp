#include "hough_plane_detector/core/hough_parameterization.h"

#include <cmath>

namespace hough_plane_detector
{

namespace
{
constexpr double kHalfPi = 1.57079632679489661923;
constexpr double kPi = 3.14159265358979323846;

// sin(x) / x, exact near 0.
double sinc(double x)
{
  return std::abs(x) < 1e-6 ? 1.0 - x * x / 6.0 : std::sin(x) / x;
}
}  // namespace

HoughParameterization::HoughParameterization(double angle_step, double d_step, double max_distance,
                                             int margin_cells)
  : angle_step_(angle_step), d_step_(d_step), max_distance_(max_distance)
{
  margin_ = margin_cells * angle_step_;
  angle_extent_ = kHalfPi + margin_;
  size_angle_ = static_cast<int>(std::ceil(2.0 * angle_extent_ / angle_step_));
  size_d_ = static_cast<int>(std::ceil(2.0 * max_distance_ / d_step_));
  // Pole at 35 deg elevation, 30 deg azimuth: floor and x/y walls sit 45-66 deg from it, far
  // from the border; the border meets horizontal normals only at azimuths 120 and -60 deg.
  const double elevation = 35.0 * kPi / 180.0, azimuth = 30.0 * kPi / 180.0;
  const Eigen::Vector3d pole(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                             std::sin(elevation));
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(pole, Eigen::Vector3d::UnitZ());
  world_to_chart_ = q.toRotationMatrix();
}

Eigen::Vector3d HoughParameterization::toHough(const Eigen::Vector3d& normal, double d) const
{
  Eigen::Vector3d n = world_to_chart_ * normal;
  if (n.z() < 0.0)
  {
    n = -n;
    d = -d;
  }
  const double theta = std::acos(std::min(1.0, n.z()));
  const double s = sinc(theta);
  return Eigen::Vector3d(n.x() / s, n.y() / s, d);
}

bool HoughParameterization::mirror(const Eigen::Vector3d& hough, Eigen::Vector3d& mirrored) const
{
  const double theta = std::hypot(hough.x(), hough.y());
  if (theta < kHalfPi - margin_ || theta > kHalfPi + margin_ || theta <= 0.0) return false;
  // -n has theta' = pi - theta and the opposite azimuth.
  const double scale = -(kPi - theta) / theta;
  mirrored = Eigen::Vector3d(hough.x() * scale, hough.y() * scale, -hough.z());
  return true;
}

bool HoughParameterization::isCanonical(const Eigen::Vector3d& hough) const
{
  return std::hypot(hough.x(), hough.y()) <= kHalfPi;
}

void HoughParameterization::fromHough(const Eigen::Vector3d& hough, Eigen::Vector3d& normal, double& d) const
{
  const double theta = std::hypot(hough.x(), hough.y());
  const double s = sinc(theta);
  const Eigen::Vector3d n(hough.x() * s, hough.y() * s, std::cos(theta));
  normal = (world_to_chart_.transpose() * n).normalized();
  d = hough.z();
}

Eigen::Vector3d HoughParameterization::toCell(const Eigen::Vector3d& hough) const
{
  return Eigen::Vector3d((hough.x() + angle_extent_) / angle_step_ - 0.5, (hough.y() + angle_extent_) / angle_step_ - 0.5,
                         (hough.z() + max_distance_) / d_step_ - 0.5);
}

Eigen::Vector3d HoughParameterization::fromCell(const Eigen::Vector3d& cell) const
{
  return Eigen::Vector3d((cell.x() + 0.5) * angle_step_ - angle_extent_, (cell.y() + 0.5) * angle_step_ - angle_extent_,
                         (cell.z() + 0.5) * d_step_ - max_distance_);
}

}  // namespace hough_plane_detector
