#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hough_plane_detector/core/hough_parameterization.h"

using hough_plane_detector::HoughParameterization;

namespace
{
constexpr double kHalfPi = 1.57079632679489661923;

HoughParameterization makeParam()
{
  return HoughParameterization(2.0 * M_PI / 1024, 10.0 / 1024, 10.0, 6);
}

// The same plane, whatever the sign of (n, d).
void expectSamePlane(const Eigen::Vector3d& n1, double d1, const Eigen::Vector3d& n2, double d2, double tol)
{
  const double sign = n1.dot(n2) >= 0 ? 1.0 : -1.0;
  EXPECT_NEAR((n1 - sign * n2).norm(), 0.0, tol) << n1.transpose() << " vs " << n2.transpose();
  EXPECT_NEAR(d1, sign * d2, tol);
}

// Normals exactly perpendicular to the chart pole: the canonical-sign border.
Eigen::Vector3d borderNormal(const HoughParameterization& p, double angle)
{
  const Eigen::Vector3d pole = p.pole();
  const Eigen::Vector3d a = pole.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d b = pole.cross(a).normalized();
  return std::cos(angle) * a + std::sin(angle) * b;
}
}  // namespace

TEST(HoughParameterization, RoundTripsRandomPlanes)
{
  const HoughParameterization p = makeParam();
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> ud(-9.0, 9.0);
  for (int i = 0; i < 2000; ++i)
  {
    const Eigen::Vector3d n = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const double d = ud(rng);
    const Eigen::Vector3d h = p.toHough(n, d);
    EXPECT_TRUE(p.isCanonical(h));
    Eigen::Vector3d n2;
    double d2;
    p.fromHough(h, n2, d2);
    expectSamePlane(n, d, n2, d2, 1e-9);
  }
}

TEST(HoughParameterization, BothSignsOfAPlaneMapToOnePoint)
{
  const HoughParameterization p = makeParam();
  for (const Eigen::Vector3d& n : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0),
                                   Eigen::Vector3d(0.3, -0.5, 0.8).normalized()})
  {
    EXPECT_NEAR((p.toHough(n, 1.5) - p.toHough(-n, -1.5)).norm(), 0.0, 1e-12);
  }
}

TEST(HoughParameterization, FloorsAndWallsAreFarFromPoleAndBorder)
{
  const HoughParameterization p = makeParam();
  for (const Eigen::Vector3d& n : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)})
  {
    const double theta = p.toHough(n, 0.0).head<2>().norm();
    EXPECT_GT(theta, 0.5) << n.transpose();
    EXPECT_LT(theta, kHalfPi - 0.3) << n.transpose();
  }
}

TEST(HoughParameterization, PoleIsARegularPoint)
{
  // Normals a little off the pole in any direction land a little off the chart centre, at
  // their true angular distance: no singularity, no smearing over alpha.
  const HoughParameterization p = makeParam();
  const Eigen::Vector3d pole = p.pole();
  EXPECT_NEAR(p.toHough(pole, 0.0).head<2>().norm(), 0.0, 1e-9);
  const Eigen::Vector3d a = pole.cross(Eigen::Vector3d::UnitX()).normalized(), b = pole.cross(a);
  for (int k = 0; k < 16; ++k)
  {
    const double phi = k * M_PI / 8;
    const Eigen::Vector3d n = (pole + 0.01 * (std::cos(phi) * a + std::sin(phi) * b)).normalized();
    EXPECT_NEAR(p.toHough(n, 0.0).head<2>().norm(), std::atan(0.01), 1e-9);
  }
}

TEST(HoughParameterization, BorderPlanesHaveMirroredTwinsInTheMargin)
{
  const HoughParameterization p = makeParam();
  for (int k = 0; k < 12; ++k)
  {
    const Eigen::Vector3d n = borderNormal(p, k * M_PI / 6);
    const Eigen::Vector3d h = p.toHough(n, 2.0);
    Eigen::Vector3d mirrored;
    ASSERT_TRUE(p.mirror(h, mirrored));
    Eigen::Vector3d n1, n2;
    double d1, d2;
    p.fromHough(h, n1, d1);
    p.fromHough(mirrored, n2, d2);
    expectSamePlane(n1, d1, n2, d2, 1e-9);
    // A hair inside the border the twin lies just outside it, a cell-sized step away in the chart.
    const Eigen::Vector3d inside = (n + 1e-3 * p.pole()).normalized();
    const Eigen::Vector3d hi = p.toHough(inside, 2.0);
    ASSERT_TRUE(p.mirror(hi, mirrored));
    EXPECT_TRUE(p.isCanonical(hi));
    EXPECT_FALSE(p.isCanonical(mirrored));
    EXPECT_NEAR(mirrored.head<2>().norm() - kHalfPi, kHalfPi - hi.head<2>().norm(), 1e-9);
  }
  // Far from the border there is no twin.
  Eigen::Vector3d unused;
  EXPECT_FALSE(p.mirror(p.toHough(Eigen::Vector3d::UnitZ(), 0.0), unused));
}

TEST(HoughParameterization, CellsCoverTheChartAndDistanceRange)
{
  const HoughParameterization p = makeParam();
  EXPECT_NEAR(p.angleStep(), 2.0 * M_PI / 1024, 1e-12);
  EXPECT_GE(p.sizeAngle() * p.angleStep(), 2.0 * (kHalfPi + p.borderMargin()) - 1e-9);
  EXPECT_GE(p.sizeD() * p.dStep(), 20.0 - 1e-9);
  const Eigen::Vector3d h(0.3, -0.2, 1.234);
  EXPECT_NEAR((p.fromCell(p.toCell(h)) - h).norm(), 0.0, 1e-12);
  const Eigen::Vector3d corner = p.toCell(Eigen::Vector3d(-p.angleExtent(), -p.angleExtent(), -p.maxDistance()));
  EXPECT_NEAR(corner.x(), -0.5, 1e-9);
  EXPECT_NEAR(corner.z(), -0.5, 1e-9);
}
