// The frame in progress as the per-frame stages see it: the normal estimator's windows and
// blocks with their noise statistics, the camera pose, and which blocks a plane of this
// frame has taken. PlaneDetector owns it and refreshes it every frame.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hough_plane_detector/core/block_regions.h"
#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/normal_estimator.h"
#include "hough_plane_detector/core/sensor_model.h"

namespace hough_plane_detector
{

struct FrameData
{
  NormalEstimator normals;
  std::vector<WindowSample> samples;  // planar windows (world frame)
  std::vector<BlockInfo> blocks;      // per block of normals' grid, camera frame
  DepthNoiseModel noise;              // the sensor's, for this frame
  Eigen::Isometry3d camera_to_world = Eigen::Isometry3d::Identity();
  std::vector<char> block_claim;  // blocks taken by an earlier plane of this frame

  // Measures a cloud: windows' normals, blocks and their noise statistics, with `noise` and
  // the parameters' window, stride and planarity limits.
  // Blocks and windows are shared out over `team`'s threads (the same result for any number).
  void measure(const CloudView& cloud, const Eigen::Isometry3d& pose, const DetectorParams& params,
               const DepthNoiseModel& sensor_noise, ThreadTeam& team = ThreadTeam::callingThreadOnly());
  // measure() in steps, for a caller that shares the blocks' rows out with other work: the
  // windows (samples, block sums), then the blocks sized, then each row's statistics.
  void measureWindows(const CloudView& cloud, const Eigen::Isometry3d& pose, const DetectorParams& params,
                      const DepthNoiseModel& sensor_noise, ThreadTeam& team);
  void sizeBlocks() { blocks.resize(static_cast<size_t>(blocksX()) * blocksY()); }
  void describeBlockRow(const DetectorParams& params, int row)
  {
    hough_plane_detector::describeBlockRow(normals, params, noise, row, blocks);
  }

  int blocksX() const { return normals.blocksX(); }
  int blocksY() const { return normals.blocksY(); }
  const PointMoments& moments(int block) const { return normals.block(block); }
  double points(int block) const { return moments(block).count; }
  // A world plane (normal, d) in the camera frame, where the blocks are.
  Eigen::Vector3d normalInCamera(const Eigen::Vector3d& normal) const { return camera_to_world.linear().transpose() * normal; }
  double dInCamera(const Eigen::Vector3d& normal, double d) const { return d + normal.dot(camera_to_world.translation()); }
  // And back: a camera-frame normal in the world frame, and the world d of that world normal.
  Eigen::Vector3d normalInWorld(const Eigen::Vector3d& n_cam) const { return camera_to_world.linear() * n_cam; }
  double dInWorld(const Eigen::Vector3d& normal, double d_cam) const { return d_cam - normal.dot(camera_to_world.translation()); }
};

}  // namespace hough_plane_detector
