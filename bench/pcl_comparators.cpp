#include "pcl_comparators.h"

#include <algorithm>
#include <cmath>

#include <pcl/ModelCoefficients.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "stopwatch.h"

namespace hough_plane_detector
{

pcl::PointCloud<pcl::PointXYZ>::Ptr toPclCloud(const CloudView& view)
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>(view.width, view.height));
  for (int v = 0; v < view.height; ++v)
    for (int u = 0; u < view.width; ++u)
    {
      auto& p = cloud->at(u, v);
      view.point(u, v, p.x, p.y, p.z);
    }
  cloud->is_dense = false;
  return cloud;
}

std::vector<EvaluatedPlane> planesToWorld(const std::vector<Eigen::Vector4d>& camera_planes, const Eigen::Isometry3d& pose)
{
  std::vector<EvaluatedPlane> out;
  for (const auto& c : camera_planes)
  {
    const Eigen::Vector3d n = (pose.linear() * c.head<3>()).normalized();
    const double d = c(3) / c.head<3>().norm() - n.dot(pose.translation());
    out.push_back({n, d});
  }
  return out;
}

std::vector<Eigen::Vector4d> pclRansacPlanes(const pcl::PointCloud<pcl::PointXYZ>::Ptr& organized, int max_iterations,
                                             double threshold, int min_inliers)
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr rest(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& p : organized->points)
    if (std::isfinite(p.z)) rest->push_back(p);
  std::vector<Eigen::Vector4d> planes;
  pcl::SACSegmentation<pcl::PointXYZ> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setMaxIterations(max_iterations);
  seg.setDistanceThreshold(threshold);
  while (static_cast<int>(rest->size()) >= min_inliers && planes.size() < 20)
  {
    pcl::PointIndices::Ptr inliers(new pcl::PointIndices);
    pcl::ModelCoefficients coefficients;
    seg.setInputCloud(rest);
    seg.segment(*inliers, coefficients);
    if (static_cast<int>(inliers->indices.size()) < min_inliers) break;
    planes.emplace_back(coefficients.values[0], coefficients.values[1], coefficients.values[2], coefficients.values[3]);
    pcl::ExtractIndices<pcl::PointXYZ> extract;
    extract.setInputCloud(rest);
    extract.setIndices(inliers);
    extract.setNegative(true);
    pcl::PointCloud<pcl::PointXYZ>::Ptr next(new pcl::PointCloud<pcl::PointXYZ>);
    extract.filter(*next);
    rest = next;
  }
  return planes;
}

std::vector<Eigen::Vector4d> pclOrganizedPlanes(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud, int min_inliers)
{
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setNormalEstimationMethod(ne.COVARIANCE_MATRIX);
  ne.setMaxDepthChangeFactor(0.02f);
  ne.setNormalSmoothingSize(10.0f);
  ne.setInputCloud(cloud);
  ne.compute(*normals);
  pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> mps;
  mps.setMinInliers(min_inliers);
  mps.setAngularThreshold(0.017453 * 3.0);
  mps.setDistanceThreshold(0.02);
  mps.setInputNormals(normals);
  mps.setInputCloud(cloud);
  std::vector<pcl::PlanarRegion<pcl::PointXYZ>, Eigen::aligned_allocator<pcl::PlanarRegion<pcl::PointXYZ>>> regions;
  mps.segmentAndRefine(regions);
  std::vector<Eigen::Vector4d> planes;
  for (const auto& r : regions) planes.push_back(r.getCoefficients().cast<double>());
  return planes;
}

double median(std::vector<double> v)
{
  return percentile(std::move(v), 0.5);
}

double percentile(std::vector<double> v, double p)
{
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * v.size()))];
}

double mean(const std::vector<double>& v)
{
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / v.size();
}

double standardDeviation(const std::vector<double>& v)
{
  if (v.size() < 2) return 0.0;
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

void MethodStats::add(const FrameMetrics& m)
{
  ++frames;
  visible += m.visible;
  detected += m.detected;
  false_detections += m.false_detections;
  angle.insert(angle.end(), m.angle_errors.begin(), m.angle_errors.end());
  d.insert(d.end(), m.d_errors.begin(), m.d_errors.end());
  for (int t : m.missed) ++missed_by_plane[t];
}

void MethodStats::merge(const MethodStats& other)
{
  ms.insert(ms.end(), other.ms.begin(), other.ms.end());
  angle.insert(angle.end(), other.angle.begin(), other.angle.end());
  d.insert(d.end(), other.d.begin(), other.d.end());
  visible += other.visible;
  detected += other.detected;
  false_detections += other.false_detections;
  frames += other.frames;
}

void runComparators(const RenderedFrame& frame, const std::vector<TruePlane>& truth, int ransac_iterations,
                    double ransac_threshold, int min_inliers, MethodStats& ransac, MethodStats& organized)
{
  const auto cloud = toPclCloud(frame.view());
  auto t = Clock::now();
  const auto r = pclRansacPlanes(cloud, ransac_iterations, ransac_threshold, min_inliers);
  ransac.ms.push_back(msSince(t));
  ransac.add(evaluateFrame(truth, frame.visible_points, min_inliers, planesToWorld(r, frame.camera_to_world)));
  t = Clock::now();
  const auto o = pclOrganizedPlanes(cloud, min_inliers);
  organized.ms.push_back(msSince(t));
  organized.add(evaluateFrame(truth, frame.visible_points, min_inliers, planesToWorld(o, frame.camera_to_world)));
}

}  // namespace hough_plane_detector
