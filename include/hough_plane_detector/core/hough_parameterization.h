// Maps planes n.p + d = 0 to Hough coordinates h = (alpha, beta, d) and back.
//
// The paper's Euler angles have two poles and a wrap border, and in a z-up world floors and
// walls land on them. Here (alpha, beta) = theta * (cos phi, sin phi), where theta and phi are
// the polar angles of the normal about an oblique chart pole (an azimuthal-equidistant chart):
// it has no singular pole at all, and the canonical sign (theta <= pi/2) leaves one border,
// theta = pi/2, where n and -n meet. Cells within `margin` of that border are stored twice
// (the mirror (-n, -d) too), so a plane on the border keeps a whole neighbourhood.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace hough_plane_detector
{

class HoughParameterization
{
public:
  HoughParameterization(double angle_step, double d_step, double max_distance, int margin_cells);

  // Continuous Hough coordinates (alpha, beta, d) of the canonical sign of (n, d); |n| = 1.
  Eigen::Vector3d toHough(const Eigen::Vector3d& normal, double d) const;
  // The same plane seen from the other sign, when it lies inside the border margin.
  bool mirror(const Eigen::Vector3d& hough, Eigen::Vector3d& mirrored) const;
  // True when the coordinates are in the canonical half (theta <= pi/2).
  bool isCanonical(const Eigen::Vector3d& hough) const;
  // Plane of Hough coordinates; the normal has unit length.
  void fromHough(const Eigen::Vector3d& hough, Eigen::Vector3d& normal, double& d) const;

  // Continuous cell coordinates (cell centres at integers) of Hough coordinates and back.
  Eigen::Vector3d toCell(const Eigen::Vector3d& hough) const;
  Eigen::Vector3d fromCell(const Eigen::Vector3d& cell) const;

  int sizeAngle() const { return size_angle_; }
  int sizeD() const { return size_d_; }
  double angleStep() const { return angle_step_; }
  double dStep() const { return d_step_; }
  double angleExtent() const { return angle_extent_; }
  double maxDistance() const { return max_distance_; }
  double borderMargin() const { return margin_; }
  // The chart's pole: the normal with alpha = beta = 0, chosen away from floors and walls.
  Eigen::Vector3d pole() const { return world_to_chart_.transpose() * Eigen::Vector3d::UnitZ(); }

private:
  double angle_step_;
  double d_step_;
  double max_distance_;
  double margin_;
  double angle_extent_;  // alpha and beta span [-angle_extent_, angle_extent_]
  int size_angle_;
  int size_d_;
  Eigen::Matrix3d world_to_chart_;
};

}  // namespace hough_plane_detector
