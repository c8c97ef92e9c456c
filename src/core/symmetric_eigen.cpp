#include "hough_plane_detector/core/symmetric_eigen.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace hough_plane_detector
{

namespace
{
SmallestEigenpair closedForm(const Eigen::Matrix3d& covariance)
{
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  SmallestEigenpair result;
  result.values = solver.eigenvalues();
  result.vector = solver.eigenvectors().col(0);
  return result;
}
}  // namespace

SmallestEigenpair smallestEigenpair(const Eigen::Matrix3d& covariance)
{
  // Scaled to unit largest entry, so the tolerances below are relative.
  const double scale = covariance.cwiseAbs().maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) return closedForm(covariance);
  const Eigen::Matrix3d a = covariance / scale;
  // det(l I - a) = l^3 - trace l^2 + minors l - det.
  const double trace = a.trace();
  const double minors = a(0, 0) * a(1, 1) - a(0, 1) * a(0, 1) + a(0, 0) * a(2, 2) - a(0, 2) * a(0, 2) +
                        a(1, 1) * a(2, 2) - a(1, 2) * a(1, 2);
  const double det = a.determinant();
  // Halley's steps from 0 (cubic convergence; 4 to 5 steps on a Kinect's blocks, Newton's
  // need 7): below the smallest root the cubic is rising and concave, and the step's
  // denominator stays positive there ((ab + bc + ca)^2 >= 3abc(a + b + c) for the gaps a, b, c).
  double smallest = 0.0;
  for (int iteration = 0; iteration < 64; ++iteration)
  {
    const double value = ((smallest - trace) * smallest + minors) * smallest - det;
    const double slope = (3.0 * smallest - 2.0 * trace) * smallest + minors;
    const double bend = 6.0 * smallest - 2.0 * trace;
    const double denominator = 2.0 * slope * slope - value * bend;
    if (!(slope > 0.0) || !(denominator > 0.0)) return closedForm(covariance);  // rank one or worse
    const double step = 2.0 * value * slope / denominator;
    smallest -= step;
    if (std::abs(step) <= 1e-13 * trace) break;
  }
  // The other two: their sum and product follow from the trace and the minors.
  const double sum = trace - smallest, product = minors - smallest * sum;
  const double half_gap = std::sqrt(std::max(0.0, 0.25 * sum * sum - product));
  Eigen::Matrix3d shifted = a;
  shifted.diagonal().array() -= smallest;
  const Eigen::Vector3d c01 = shifted.row(0).cross(shifted.row(1)), c02 = shifted.row(0).cross(shifted.row(2)),
                        c12 = shifted.row(1).cross(shifted.row(2));
  const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
  const double longest = std::max(n01, std::max(n02, n12));
  // The cross product's length is about the product of the other two eigenvalues' gaps to the
  // smallest: a gap under 1e-6 of the trace leaves the direction to rounding.
  if (!(longest > 1e-12 * trace * trace * trace * trace)) return closedForm(covariance);
  SmallestEigenpair result;
  result.values << smallest, 0.5 * sum - half_gap, 0.5 * sum + half_gap;
  result.values *= scale;
  result.vector = (n01 == longest ? c01 : n02 == longest ? c02 : c12) / std::sqrt(longest);
  return result;
}

}  // namespace hough_plane_detector
