// Per-stage timing and memory of the detector on VGA frames, with PCL's RANSAC and organized
// multi-plane segmentation run in the same process on the same frames. Prints figures; it is
// not a test. Usage: benchmark_detector [FRAME.pcd ...]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <pcl/ModelCoefficients.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/core/plane_metrics.h"
#include "hough_plane_detector/core/scene_renderer.h"
#include "hough_plane_detector/tools/input_sources.h"

using namespace hough_plane_detector;
using Clock = std::chrono::steady_clock;

namespace
{
double msSince(Clock::time_point t)
{
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double median(std::vector<double> v)
{
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
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

pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const CloudView& view)
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

std::vector<EvaluatedPlane> toWorld(const std::vector<Eigen::Vector4d>& camera_planes, const Eigen::Isometry3d& pose)
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

// The paper's comparator: iterative RANSAC, each plane refined by least squares, its inliers removed.
std::vector<Eigen::Vector4d> pclRansac(const pcl::PointCloud<pcl::PointXYZ>::Ptr& organized, int max_iterations,
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

// PCL's organized segmentation with integral-image normals (its tutorial settings).
std::vector<Eigen::Vector4d> pclOrganized(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud, int min_inliers)
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

struct MethodStats
{
  std::vector<double> ms, angle, d;
  int visible = 0, detected = 0, false_detections = 0, frames = 0;
  void add(const FrameMetrics& m)
  {
    ++frames;
    visible += m.visible;
    detected += m.detected;
    false_detections += m.false_detections;
    angle.insert(angle.end(), m.angle_errors.begin(), m.angle_errors.end());
    d.insert(d.end(), m.d_errors.begin(), m.d_errors.end());
  }
  void print(const char* name) const
  {
    std::printf("  %-34s %8.2f %8.2f %8.2f   %.4f   %.4f   %5.1f %%   %.2f\n", name, median(ms), percentile(ms, 0.1),
                percentile(ms, 0.9), mean(angle), mean(d), visible ? 100.0 * detected / visible : 0.0,
                frames ? static_cast<double>(false_detections) / frames : 0.0);
  }
};
}  // namespace

int main(int argc, char** argv)
{
  const int frames = 40;
  std::printf("hough_plane_detector benchmark: one core, 640 x 480 frames, default parameters\n\n");
  SceneRenderer renderer(makeOfficeRoom());
  KinectNoise noise;
  noise.coefficient = 1.0;
  const auto poses = roomTour(frames);
  std::vector<RenderedFrame> rendered;
  for (int f = 0; f < frames; ++f) rendered.push_back(renderer.render(poses[f], noise, 500 + f));

  // Ours: two laps so the medians are of a warmed-up map; accuracy from frame 3 of lap one.
  PlaneDetector detector{DetectorParams()};
  std::vector<double> stage[6];
  MethodStats ours;
  for (int lap = 0; lap < 2; ++lap)
    for (int f = 0; f < frames; ++f)
    {
      detector.processFrame(rendered[f].view(), rendered[f].camera_to_world, lap * frames + f);
      const StageTimings& t = detector.lastTimings();
      const double values[6] = {t.normals_ms, t.voting_ms, t.blur_ms, t.peaks_ms, t.global_ms, t.total_ms};
      for (int i = 0; i < 6; ++i) stage[i].push_back(values[i]);
      ours.ms.push_back(t.total_ms);
      if (lap == 0 && f < 3) continue;
      std::vector<EvaluatedPlane> evaluated;
      for (const auto& p : detector.planes()) evaluated.push_back({p.normal, p.d});
      ours.add(evaluateFrame(renderer.truePlanes(), rendered[f].visible_points, 2000, evaluated));
    }
  const char* names[6] = {"normals", "voting", "blur", "local peaks + fits", "global update", "total"};
  std::printf("rendered office tour, Kinect noise C = 1.0, %d frames x 2 laps; median ms per stage:\n", frames);
  for (int i = 0; i < 6; ++i) std::printf("  %-20s %6.3f ms\n", names[i], median(stage[i]));
  const MemoryReport mem = detector.memory();
  std::printf("Hough space (resolution 1024): %.2f MB in %zu chunks = %.3f %% of the dense %.0f MB array "
              "(%.4f %% of a 1024^3 float array)\n\n",
              mem.global_bytes / 1e6, mem.global_chunks, 100.0 * mem.global_bytes / mem.dense_bytes, mem.dense_bytes / 1e6,
              100.0 * mem.global_bytes / (1024.0 * 1024.0 * 1024.0 * 4.0));

  // Comparators on every 4th frame (RANSAC is slow), in the same process.
  MethodStats ransac, organized;
  for (int f = 0; f < frames; f += 4)
  {
    auto cloud = toPcl(rendered[f].view());
    auto t = Clock::now();
    const auto r = pclRansac(cloud, 500, 0.02, 2000);
    ransac.ms.push_back(msSince(t));
    ransac.add(evaluateFrame(renderer.truePlanes(), rendered[f].visible_points, 2000, toWorld(r, rendered[f].camera_to_world)));
    t = Clock::now();
    const auto o = pclOrganized(cloud, 2000);
    organized.ms.push_back(msSince(t));
    organized.add(evaluateFrame(renderer.truePlanes(), rendered[f].visible_points, 2000,
                                toWorld(o, rendered[f].camera_to_world)));
  }
  std::printf("accuracy and time on the rendered frames (planes with >= 2000 visible points):\n");
  std::printf("  %-34s %8s %8s %8s   %-6s   %-6s   %-7s   %s\n", "method", "median", "p10", "p90", "E_ang", "E_d",
              "found", "false/frame");
  ours.print("hough_plane_detector (map)");
  ransac.print("PCL RANSAC (2 cm, 500 it, LSQ)");
  organized.print("PCL OrganizedMultiPlaneSegm.");
  std::printf("  speed-up: %.1fx vs PCL RANSAC, %.1fx vs PCL organized segmentation\n\n",
              median(ransac.ms) / median(ours.ms), median(organized.ms) / median(ours.ms));

  // Real Kinect frames, a still camera.
  if (argc > 1)
  {
    PlaneDetector real{DetectorParams()};
    std::vector<double> ours_ms, ransac_ms, organized_ms;
    size_t ours_planes = 0, ransac_planes = 0, organized_planes = 0;
    for (int rep = 0; rep < 5; ++rep)
      for (int i = 1; i < argc; ++i)
      {
        pcl::PCLPointCloud2 blob;
        std::string error;
        if (!loadPcd(argv[i], blob, &error))
        {
          std::fprintf(stderr, "%s\n", error.c_str());
          return 1;
        }
        CloudView view;
        std::vector<float> converted;
        error = makeCloudView(layoutOf(blob), view, converted);
        if (!error.empty() || !real.processFrame(view, Eigen::Isometry3d::Identity(), rep * argc + i, &error))
        {
          std::fprintf(stderr, "%s: %s\n", argv[i], error.c_str());
          return 1;
        }
        ours_ms.push_back(real.lastTimings().total_ms);
        ours_planes = real.planes().size();
        if (rep > 0) continue;
        auto cloud = toPcl(view);
        auto t = Clock::now();
        ransac_planes = pclRansac(cloud, 500, 0.02, 2000).size();
        ransac_ms.push_back(msSince(t));
        t = Clock::now();
        organized_planes = pclOrganized(cloud, 2000).size();
        organized_ms.push_back(msSince(t));
      }
    std::printf("real Kinect frames (%d PCD files, still camera): median ms per frame and planes found\n", argc - 1);
    std::printf("  %-34s %8.2f ms  %zu planes in the map\n", "hough_plane_detector", median(ours_ms), ours_planes);
    std::printf("  %-34s %8.2f ms  %zu planes (last frame)\n", "PCL RANSAC (2 cm, 500 it, LSQ)", median(ransac_ms), ransac_planes);
    std::printf("  %-34s %8.2f ms  %zu planes (last frame)\n", "PCL OrganizedMultiPlaneSegm.", median(organized_ms),
                organized_planes);
    std::printf("  speed-up: %.1fx vs PCL RANSAC, %.1fx vs PCL organized segmentation\n", median(ransac_ms) / median(ours_ms),
                median(organized_ms) / median(ours_ms));
    for (const auto& p : real.planes())
      std::printf("    plane %d: n = (%+.3f %+.3f %+.3f), d = %+.3f, support %d\n", p.id, p.normal.x(), p.normal.y(),
                  p.normal.z(), p.d, p.support);
  }
  return 0;
}
