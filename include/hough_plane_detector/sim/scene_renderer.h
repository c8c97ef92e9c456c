// A synthetic Kinect: rooms of rectangles, boxes and curved clutter ray-cast into 640 x 480
// organized clouds with the paper's distance-dependent noise (eq. 11) and disparity
// quantization, plus the ground-truth planes of every frame.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hough_plane_detector/core/camera_intrinsics.h"
#include "hough_plane_detector/core/cloud_view.h"

namespace hough_plane_detector
{

struct SceneRectangle
{
  Eigen::Vector3d center;
  Eigen::Vector3d axis_u;  // unit
  Eigen::Vector3d axis_v;  // unit, orthogonal to axis_u
  double half_u;
  double half_v;
  std::string name;
};

struct SceneCylinder  // vertical
{
  Eigen::Vector3d base;
  double radius;
  double height;
};

struct SceneSphere
{
  Eigen::Vector3d center;
  double radius;
};

struct TruePlane
{
  Eigen::Vector3d normal;  // unit
  double d;                // normal.p + d = 0
  std::string name;
};

struct Scene
{
  std::vector<SceneRectangle> rectangles;
  std::vector<SceneCylinder> cylinders;
  std::vector<SceneSphere> spheres;

  void addRectangle(const Eigen::Vector3d& center, const Eigen::Vector3d& axis_u, const Eigen::Vector3d& axis_v,
                    double half_u, double half_v, const std::string& name);
  // A box standing on z = center.z - half.z, turned by yaw; its bottom face is left out.
  void addBox(const Eigen::Vector3d& center, const Eigen::Vector3d& half, double yaw, const std::string& name);
  // Floor (z = 0), ceiling and four walls of a room 2 half_x by 2 half_y about the origin, x
  // east, y north: "floor", "ceiling", "wall_east", "wall_west", "wall_north", "wall_south".
  void addRoom(double half_x, double half_y, double height);
  // Distinct infinite planes of the rectangles (coplanar rectangles are one plane), and for
  // each rectangle the index of its plane.
  std::vector<TruePlane> truePlanes(std::vector<int>* rectangle_plane = nullptr) const;
};

struct KinectNoise
{
  double coefficient = 1.0;  // C_noc of eq. 11; 1.0 is about a real Kinect (C = 0 still leaves 2.7 mm)
  bool gaussian = true;      // false: exact depths, for tests of geometry alone
  bool quantize = true;      // 11-bit disparity in 1/8 pixel steps
  double baseline = 0.075;   // m
  double subpixel = 8.0;
  // Real structured-light noise is spatially correlated (a disparity is matched over a window of
  // pixels). With correlation_px > 0 the noise is a Gaussian-smoothed field of that many pixels
  // (sigma) carrying `correlated_variance` of eq. 11's variance, plus an independent share
  // `independent_variance`. At 8 px, 0.16 and 0.05 give a block's spread along its plane of 0.04
  // of eq. 11's sigma^2, as osd-learn's tables show 0.052 (evaluate_osd --noise); their block
  // centroids stray further still (3 times the modelled variance, this field about half of it).
  // 0 (default): all of it independent per pixel.
  double correlation_px = 0.0;
  double correlated_variance = 0.16;
  double independent_variance = 0.05;
};

struct RenderedFrame
{
  int width = 0;
  int height = 0;
  std::vector<float> xyz;               // camera optical frame, NaN where no return
  std::vector<int> pixel_plane;         // true-plane index per pixel, -1 for clutter or none
  std::vector<int> visible_points;      // per true plane
  Eigen::Isometry3d camera_to_world = Eigen::Isometry3d::Identity();

  CloudView view() const;
};

class SceneRenderer
{
public:
  explicit SceneRenderer(const Scene& scene, const CameraIntrinsics& intrinsics = CameraIntrinsics());
  RenderedFrame render(const Eigen::Isometry3d& camera_to_world, const KinectNoise& noise, uint32_t seed) const;
  const std::vector<TruePlane>& truePlanes() const { return true_planes_; }
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }

private:
  Scene scene_;
  CameraIntrinsics intrinsics_;
  std::vector<TruePlane> true_planes_;
  std::vector<int> rectangle_plane_;
};

// Standard deviation of Kinect depth noise in metres at true depth z (eq. 11).
double kinectNoiseSigma(double depth, double coefficient);

// Camera optical frame (z forward, x right, y down) at `eye` looking at `target`, z-up world.
Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target);

// A 6 x 5 x 2.8 m room: floor, four walls, ceiling, a table, a cabinet, a shelf, curved clutter.
Scene makeOfficeRoom();
// A 8 x 6 x 3 m hall with a ramp 10 deg off the floor, stairs of 15 cm treads, a door
// recessed 10 cm into its wall and curved clutter.
Scene makeRampStairsHall();
// A 5 x 4 x 2.6 m lab: floor, ceiling, four walls, two desks, two cabinets, a crate, and bins,
// a pillar and balls that are not planar.
Scene makeClutteredLab();
// A still camera turning around the room centre: `frames` poses at 1.0 m height.
std::vector<Eigen::Isometry3d> roomTour(int frames, const Eigen::Vector3d& centre = Eigen::Vector3d(0, 0, 1.0),
                                        double radius = 0.5);
// A camera driving straight at the wall x = wall_x from start_distance to end_distance.
std::vector<Eigen::Isometry3d> wallApproach(int frames, double wall_x, double start_distance, double end_distance);

}  // namespace hough_plane_detector
