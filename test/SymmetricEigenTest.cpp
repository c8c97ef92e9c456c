#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "hough_plane_detector/core/plane_geometry.h"
#include "hough_plane_detector/core/symmetric_eigen.h"

using namespace hough_plane_detector;

namespace
{
// A covariance with the given eigenvalues along a random rotation.
Eigen::Matrix3d rotatedDiagonal(std::mt19937& random, const Eigen::Vector3d& values, Eigen::Matrix3d* rotation = nullptr)
{
  std::normal_distribution<double> gauss;
  const Eigen::Matrix3d r =
      Eigen::Quaterniond(Eigen::Vector4d(gauss(random), gauss(random), gauss(random), gauss(random)).normalized())
          .toRotationMatrix();
  if (rotation) *rotation = r;
  return r * values.asDiagonal() * r.transpose();
}
}  // namespace

TEST(SymmetricEigen, AgreesWithEigensIterativeSolverOnPlaneLikeScatters)
{
  // Block and window scatters: thin along the normal (1e-9 .. 1e-3 of the spread), two
  // in-plane spreads of any ratio, anywhere from millimetres to metres.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> exponent(-9.0, -3.0), ratio(0.01, 1.0), size(-6.0, 0.0);
  for (int i = 0; i < 20000; ++i)
  {
    const double spread = std::pow(10.0, size(random));
    const Eigen::Vector3d values(spread * std::pow(10.0, exponent(random)), spread * ratio(random), spread);
    Eigen::Matrix3d rotation;
    const Eigen::Matrix3d covariance = rotatedDiagonal(random, values, &rotation);
    const SmallestEigenpair ours = smallestEigenpair(covariance);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> reference(covariance);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(ours.values(k), reference.eigenvalues()(k), 1e-9 * spread) << i;
    ASSERT_NEAR(ours.vector.norm(), 1.0, 1e-12);
    ASSERT_LT(unsignedAngle(ours.vector, rotation.col(0)), 1e-7) << i;
  }
}

TEST(SymmetricEigen, ExactlyFlatAndRoundingNegativeScattersKeepTheirNormal)
{
  // Points exactly on a plane have a singular scatter; moments summed in floats may leave
  // its smallest eigenvalue a rounding below zero.
  std::mt19937 random(11);
  for (double smallest : {0.0, -1e-15, 1e-15})
  {
    Eigen::Matrix3d rotation;
    const Eigen::Matrix3d covariance = rotatedDiagonal(random, Eigen::Vector3d(smallest, 0.3, 1.0), &rotation);
    const SmallestEigenpair ours = smallestEigenpair(covariance);
    EXPECT_NEAR(ours.values(0), smallest, 1e-12);
    EXPECT_NEAR(ours.values(1), 0.3, 1e-12);
    EXPECT_NEAR(ours.values(2), 1.0, 1e-12);
    EXPECT_LT(unsignedAngle(ours.vector, rotation.col(0)), 1e-7);  // acos resolves ~2e-8
  }
}

TEST(SymmetricEigen, DegenerateMatricesGiveEigensAnswer)
{
  // Two equal smallest eigenvalues (a line of points), rank one, zero, not finite: no normal
  // is defined better than Eigen's closed form defines it, so that is what comes back.
  std::mt19937 random(3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Eigen::Matrix3d> degenerate = {rotatedDiagonal(random, Eigen::Vector3d(0.2, 0.2, 1.0)),
                                             rotatedDiagonal(random, Eigen::Vector3d(0.0, 0.0, 1.0)),
                                             Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Identity(),
                                             Eigen::Matrix3d::Constant(nan)};
  for (const Eigen::Matrix3d& covariance : degenerate)
  {
    const SmallestEigenpair ours = smallestEigenpair(covariance);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> closed_form;
    closed_form.computeDirect(covariance);
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_EQ(std::isnan(ours.values(k)), std::isnan(closed_form.eigenvalues()(k)));
      if (!std::isnan(ours.values(k)))
      {
        EXPECT_EQ(ours.values(k), closed_form.eigenvalues()(k));
      }
    }
    if (covariance.allFinite())
    {
      EXPECT_TRUE(ours.vector.isApprox(closed_form.eigenvectors().col(0)));
    }
  }
}
