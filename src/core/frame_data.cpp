#include "hough_plane_detector/core/frame_data.h"

namespace hough_plane_detector
{

void FrameData::measure(const CloudView& cloud, const Eigen::Isometry3d& pose, const DetectorParams& params,
                        const DepthNoiseModel& sensor_noise, ThreadTeam& team)
{
  measureWindows(cloud, pose, params, sensor_noise, team);
  describeBlocks(normals, params, noise, blocks, team);
}

void FrameData::measureWindows(const CloudView& cloud, const Eigen::Isometry3d& pose, const DetectorParams& params,
                               const DepthNoiseModel& sensor_noise, ThreadTeam& team)
{
  camera_to_world = pose;
  noise = sensor_noise;
  NormalEstimatorConfig config;
  config.window = params.normal_window;
  config.stride = params.normal_stride;
  config.min_valid_fraction = params.min_valid_fraction;
  config.max_curvature = params.max_curvature;
  config.noise = noise;
  config.max_window_scale = params.max_window_scale;
  normals.compute(cloud, camera_to_world, config, samples, team);
  block_claim.clear();
}

}  // namespace hough_plane_detector
