// The paper's comparators from PCL (iterative RANSAC with least-squares refinement, and
// organized multi-plane segmentation) plus the small statistics both benchmarks print.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "hough_plane_detector/sim/room_statistics.h"

namespace hough_plane_detector
{

pcl::PointCloud<pcl::PointXYZ>::Ptr toPclCloud(const CloudView& view);

// Camera-frame plane coefficients (a, b, c, d) into world-frame unit-normal planes.
std::vector<EvaluatedPlane> planesToWorld(const std::vector<Eigen::Vector4d>& camera_planes, const Eigen::Isometry3d& pose);

// Iterative SACSegmentation: each plane refined by least squares and its inliers removed, until
// the best plane has fewer than min_inliers points (at most 20 planes).
std::vector<Eigen::Vector4d> pclRansacPlanes(const pcl::PointCloud<pcl::PointXYZ>::Ptr& organized, int max_iterations,
                                             double threshold, int min_inliers);

// OrganizedMultiPlaneSegmentation on integral-image normals, with PCL's tutorial settings.
std::vector<Eigen::Vector4d> pclOrganizedPlanes(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud, int min_inliers);

double median(std::vector<double> v);
double percentile(std::vector<double> v, double p);  // p in [0, 1]
double mean(const std::vector<double>& v);
double standardDeviation(const std::vector<double>& v);

// Accumulated per-frame metrics and times of one method.
struct MethodStats
{
  std::vector<double> ms, angle, d;
  int visible = 0, detected = 0, false_detections = 0, frames = 0;
  std::map<int, int> missed_by_plane;  // frames each true plane went unmatched (one scene: merge skips it)
  void add(const FrameMetrics& m);
  double detectionPercent() const { return visible ? 100.0 * detected / visible : 0.0; }
  double falsePerFrame() const { return frames ? static_cast<double>(false_detections) / frames : 0.0; }
  void merge(const MethodStats& other);
  // Its counts as one room's, for the intervals over rooms.
  RoomCounts roomCounts(const std::string& room) const { return {room, detected, visible, false_detections, frames}; }
};

// Both PCL methods on one rendered frame (planes of min_inliers points), timed and scored
// against the scene's truth with the same matching as ours.
void runComparators(const RenderedFrame& frame, const std::vector<TruePlane>& truth, int ransac_iterations,
                    double ransac_threshold, int min_inliers, MethodStats& ransac, MethodStats& organized);

}  // namespace hough_plane_detector
