// Surface normals of an organized cloud by the covariance (eigen) method over square windows,
// from an integral image of point moments summed per stride block (paper 3.2).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/thread_team.h"
#include "hough_plane_detector/core/sensor_model.h"

namespace hough_plane_detector
{

// Point moments of a set of points: count, sum of p, sum of p p^T (upper triangle).
struct PointMoments
{
  double count = 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  // Inline: region growing and the windows' summed-area table call these per block.
  void add(const PointMoments& o)
  {
    count += o.count;
    sum += o.sum;
    xx += o.xx; xy += o.xy; xz += o.xz; yy += o.yy; yz += o.yz; zz += o.zz;
  }
  void subtract(const PointMoments& o)
  {
    count -= o.count;
    sum -= o.sum;
    xx -= o.xx; xy -= o.xy; xz -= o.xz; yy -= o.yy; yz -= o.yz; zz -= o.zz;
  }
  // Weights every point by w (mean and covariance unchanged, count becomes a weight sum).
  void scale(double w)
  {
    count *= w;
    sum *= w;
    xx *= w; xy *= w; xz *= w; yy *= w; yz *= w; zz *= w;
  }
  Eigen::Vector3d mean() const { return sum / count; }
  Eigen::Matrix3d covariance() const;
  // The normal of their least-squares plane (unit, either sign); false when they lie along a
  // line (a row of blocks), which fixes no plane.
  bool planeNormal(Eigen::Vector3d& normal) const;
  // The same points moved by a rigid transform.
  PointMoments transformed(const Eigen::Isometry3d& transform) const;
};

// One window whose points are planar: its plane in the world frame.
struct WindowSample
{
  Eigen::Vector3d normal;    // world frame, pointing toward the sensor
  Eigen::Vector3d centroid;  // world frame
  double d;                  // normal.p + d = 0
  int count;                 // valid points in the window (its own, also when measured wider)
  int window_x, window_y;    // window position: its top-left block
};

struct NormalEstimatorConfig
{
  int window = 8;
  int stride = 8;
  double min_valid_fraction = 0.6;
  double max_curvature = 0.02;
  // The sensor's depth noise; a disabled model turns the noise-aware test off.
  DepthNoiseModel noise;
  // Windows whose noise is as thick as half their width are measured again over 2x, then 4x,
  // as wide a window around them, up to this factor (1: never).
  int max_window_scale = 4;
};

// Edge of the pixel blocks that carry point moments for a window and stride (<= 8 pixels).
int blockSize(int window, int stride);

class NormalEstimator
{
public:
  // Fills `samples` with one sample per planar window of the cloud, transformed to the world.
  // Block rows and window rows are shared out over `team`; the result does not depend on
  // its size.
  void compute(const CloudView& cloud, const Eigen::Isometry3d& camera_to_world, const NormalEstimatorConfig& config,
               std::vector<WindowSample>& samples, ThreadTeam& team = ThreadTeam::callingThreadOnly());

  // Camera-frame moments of the block grid (blockSize() pixel blocks) of the last cloud.
  int blocksX() const { return blocks_x_; }
  int blocksY() const { return blocks_y_; }
  const PointMoments& block(int bx, int by) const { return blocks_[static_cast<size_t>(by) * blocks_x_ + bx]; }
  // The same by its row-major index by * blocksX() + bx, as regions list their blocks.
  const PointMoments& block(int index) const { return blocks_[static_cast<size_t>(index)]; }
  // Number of windows with enough valid points in the last cloud.
  int validWindows() const { return valid_windows_; }

private:
  // Point moments of every s x s pixel block.
  void accumulateBlocks(const CloudView& cloud, int s, ThreadTeam& team);
  // The summed-area table over the blocks (when windows span several blocks).
  void buildIntegral();
  // Moments of the blocks [x0, x1) x [y0, y1), clipped to the grid.
  PointMoments windowMoments(int x0, int y0, int x1, int y1) const;
  // The normal and centre of the k x k-block window at (wx, wy), camera frame, measured over
  // up to max_window_scale times wider windows while it is as thick as half its width; false
  // when no measurement is planar.
  bool measureWindow(int wx, int wy, int k, const NormalEstimatorConfig& config, Eigen::Vector3d& normal,
                     Eigen::Vector3d& mean) const;

  int blocks_x_ = 0, blocks_y_ = 0;
  int valid_windows_ = 0;
  bool use_integral_ = false;
  std::vector<PointMoments> blocks_;
  std::vector<PointMoments> integral_;  // (blocks_x_ + 1) x (blocks_y_ + 1) summed-area table
};

}  // namespace hough_plane_detector
