// Eigen-decomposition of the 3 x 3 scatter matrices the per-frame stage fits planes to: the
// eigenvalues and the eigenvector of the smallest (the plane's normal), without the
// trigonometry of Eigen's closed form and with one eigenvector instead of three (make bench
// prints both solvers' times).
#pragma once

#include <Eigen/Core>

namespace hough_plane_detector
{

struct SmallestEigenpair
{
  Eigen::Vector3d values = Eigen::Vector3d::Zero();  // ascending
  Eigen::Vector3d vector = Eigen::Vector3d::UnitZ();  // unit, of values(0); its sign is arbitrary
};

// Of a symmetric positive semi-definite matrix (a covariance): the smallest root of the
// characteristic cubic by Halley's method from below, the other two from its coefficients,
// the eigenvector as the longest cross product of two rows of (matrix - smallest * I).
// Falls back to Eigen's closed form when the two smallest eigenvalues nearly coincide (no
// direction is then better defined than Eigen defines it) or the matrix is not finite.
SmallestEigenpair smallestEigenpair(const Eigen::Matrix3d& covariance);

}  // namespace hough_plane_detector
