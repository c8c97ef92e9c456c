// Per-stage timing and memory of the detector on VGA frames, with PCL's RANSAC and organized
// multi-plane segmentation run in the same process on the same frames. Prints figures; it is
// not a test. Usage: benchmark_detector [FRAME.pcd ...]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <pcl/PCLPointCloud2.h>

#include <Eigen/Eigenvalues>

#include "hough_plane_detector/core/normal_estimator.h"
#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/core/plane_geometry.h"
#include "hough_plane_detector/core/symmetric_eigen.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "hough_plane_detector/core/sensor_model.h"
#include "hough_plane_detector/tools/input_sources.h"
#include "pcl_comparators.h"
#include "stopwatch.h"

using namespace hough_plane_detector;

namespace
{
void printStats(const MethodStats& s, const char* name)
{
  std::printf("  %-34s %8.2f %8.2f %8.2f   %.4f   %.4f   %5.1f %%   %.2f\n", name, median(s.ms), percentile(s.ms, 0.1),
              percentile(s.ms, 0.9), mean(s.angle), mean(s.d), s.detectionPercent(), s.falsePerFrame());
}
// Ours on two laps of the tour (medians of a warmed-up map; accuracy from frame 3 of lap one):
// the stages' times printed, the scores and the detector (for its memory) returned.
MethodStats benchStages(const SceneRenderer& renderer, const std::vector<RenderedFrame>& rendered,
                        PlaneDetector& detector)
{
  const int frames = static_cast<int>(rendered.size());
  constexpr int kStages = 11;
  std::vector<double> stage[kStages];
  MethodStats ours;
  for (int lap = 0; lap < 2; ++lap)
    for (int f = 0; f < frames; ++f)
    {
      detector.processFrame(rendered[f].view(), rendered[f].camera_to_world, lap * frames + f);
      const StageTimings& t = detector.lastTimings();
      const double values[kStages] = {t.normals_ms,  t.blocks_ms,   t.voting_ms, t.blur_ms,   t.peaks_ms, t.fit_ms,
                                      t.parallel_ms, t.evidence_ms, t.global_ms, t.labels_ms, t.total_ms};
      for (int i = 0; i < kStages; ++i) stage[i].push_back(values[i]);
      ours.ms.push_back(t.total_ms);
      if (lap == 0 && f < 3) continue;
      ours.add(evaluateFrame(renderer.truePlanes(), rendered[f].visible_points, 2000, evaluatedPlanes(detector.planes())));
    }
  const char* names[kStages] = {"normals",          "blocks + Hough",   "  voting",       "  blur",
                                 "  local peaks",    "per-frame fits",   "parallel search", "evidence check",
                                 "map update",       "labels + extents", "total"};
  std::printf("rendered office tour, Kinect noise C = 1.0, %d frames x 2 laps; median ms per stage (p90); with two\n"
              "threads the blocks' statistics run beside voting, blur and local peaks (blocks + Hough: the four\n"
              "together), the evidence check beside the fits:\n",
              frames);
  for (int i = 0; i < kStages; ++i)
    std::printf("  %-20s %6.3f ms (%.3f)\n", names[i], median(stage[i]), percentile(stage[i], 0.9));
  return ours;
}

// The normals' 3 x 3 eigen-decompositions (one per 8 x 8 block and one or two per window):
// Eigen's closed form against smallestEigenpair, on the blocks of the rendered frames.
void benchEigenSolvers(const std::vector<RenderedFrame>& rendered)
{
  std::vector<Eigen::Matrix3d> scatters;
  for (const RenderedFrame& frame : rendered)
  {
    const CloudView view = frame.view();
    for (int by = 0; by + 8 <= view.height; by += 8)
      for (int bx = 0; bx + 8 <= view.width; bx += 8)
      {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        Eigen::Matrix3d squares = Eigen::Matrix3d::Zero();
        int n = 0;
        for (int v = by; v < by + 8; ++v)
          for (int u = bx; u < bx + 8; ++u)
          {
            float x, y, z;
            view.point(u, v, x, y, z);
            if (!std::isfinite(z)) continue;
            const Eigen::Vector3d p(x, y, z);
            sum += p;
            squares += p * p.transpose();
            ++n;
          }
        if (n >= 8) scatters.push_back(squares / n - (sum / n) * (sum / n).transpose());
      }
  }
  if (scatters.empty()) return;
  volatile double sink = 0.0;  // keeps the timed loop's results alive
  double worst_angle = 0.0;
  auto start = Clock::now();
  std::vector<Eigen::Vector3d> closed_form_normals;
  closed_form_normals.reserve(scatters.size());
  for (const Eigen::Matrix3d& scatter : scatters)
  {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(scatter);
    closed_form_normals.push_back(solver.eigenvectors().col(0));
  }
  const double closed_form_ns = 1e6 * msSince(start) / scatters.size();
  start = Clock::now();
  for (const Eigen::Matrix3d& scatter : scatters) sink = sink + smallestEigenpair(scatter).vector.x();
  const double ours_ns = 1e6 * msSince(start) / scatters.size();
  for (size_t i = 0; i < scatters.size(); ++i)
    worst_angle = std::max(worst_angle, unsignedAngle(smallestEigenpair(scatters[i]).vector, closed_form_normals[i]));
  std::printf("  of the normals: 3 x 3 eigen-decomposition of %zu block scatters: Eigen's closed form %.0f ns, "
              "smallestEigenpair %.0f ns (normals agree to %.1e rad)\n",
              scatters.size(), closed_form_ns, ours_ns, worst_angle);
}

// The normals' per-block sums: four pixels at a time where x, y, z are consecutive floats (the
// renderer's packed XYZ, as PCL's), against the field-by-field loop other layouts take (the
// same frames with a gap after each coordinate). Median ms of NormalEstimator::compute.
void benchBlockSums(const std::vector<RenderedFrame>& rendered)
{
  NormalEstimatorConfig config;
  config.window = 32;
  config.stride = 16;
  NormalEstimator estimator;
  std::vector<WindowSample> samples;
  std::vector<double> consecutive_ms, by_field_ms;
  for (const RenderedFrame& frame : rendered)
  {
    const CloudView packed = frame.view();
    std::vector<float> spread_xyz(2 * frame.xyz.size());
    for (size_t i = 0; i < frame.xyz.size(); ++i) spread_xyz[2 * i] = frame.xyz[i];
    CloudView spread = packed;
    spread.data = reinterpret_cast<const uint8_t*>(spread_xyz.data());
    spread.point_step = 24;
    spread.row_step = 24 * static_cast<size_t>(frame.width);
    spread.y_offset = 8;
    spread.z_offset = 16;
    for (int repeat = 0; repeat < 3; ++repeat)
    {
      auto start = Clock::now();
      estimator.compute(packed, frame.camera_to_world, config, samples);
      consecutive_ms.push_back(msSince(start));
      start = Clock::now();
      estimator.compute(spread, frame.camera_to_world, config, samples);
      by_field_ms.push_back(msSince(start));
    }
  }
  std::printf("  of the normals: block sums and window normals of a frame, x y z consecutive (four pixels at a time) "
              "%.3f ms, x y z apart (field by field) %.3f ms\n",
              median(consecutive_ms), median(by_field_ms));
}

// What the options cost on the same frames: the paper's windows instead of block regions, the
// paper's thinning instead of forgetting by evidence (its check of the map's planes against
// each frame), the measurement on one thread instead of two; fitting the projection to each
// cloud; the normals' eigen-decompositions and block sums.
void benchVariants(const std::vector<RenderedFrame>& rendered)
{
  const int frames = static_cast<int>(rendered.size());
  auto variantMedians = [&](const DetectorParams& params, std::vector<double>* evidence_ms) {
    PlaneDetector variant(params);
    std::vector<double> total;
    for (int lap = 0; lap < 2; ++lap)
      for (int f = 0; f < frames; ++f)
      {
        variant.processFrame(rendered[f].view(), rendered[f].camera_to_world, lap * frames + f);
        total.push_back(variant.lastTimings().total_ms);
        if (evidence_ms) evidence_ms->push_back(variant.lastTimings().evidence_ms);
      }
    return median(total);
  };
  DetectorParams windows, evidence, thinning;
  windows.region_growing = 0;
  evidence.forgetting = kForgetByEvidence;
  thinning.forgetting = kForgetByThinning;
  std::vector<double> evidence_ms;
  const double windows_total = variantMedians(windows, nullptr);
  const double evidence_total = variantMedians(evidence, &evidence_ms);
  const double thinning_total = variantMedians(thinning, nullptr);
  std::printf("  region_growing 0 (the paper's windows): total %6.3f ms\n", windows_total);
  std::printf("  forgetting 1 (by evidence, the default): total %6.3f ms, of which the evidence check %.3f ms (p90 %.3f)\n",
              evidence_total, median(evidence_ms), percentile(evidence_ms, 0.9));
  std::printf("  forgetting 0 (the paper's thinning): total %6.3f ms\n", thinning_total);
  // One thread against two, frame by frame in turn: this VM's speed drifts between runs.
  DetectorParams one_thread, two_threads;
  one_thread.measurement_threads = 1;
  two_threads.measurement_threads = 2;
  PlaneDetector alone(one_thread), pair(two_threads);
  std::vector<double> alone_normals, alone_total, pair_normals, pair_total;
  for (int lap = 0; lap < 2; ++lap)
    for (int f = 0; f < frames; ++f)
    {
      alone.processFrame(rendered[f].view(), rendered[f].camera_to_world, lap * frames + f);
      pair.processFrame(rendered[f].view(), rendered[f].camera_to_world, lap * frames + f);
      alone_normals.push_back(alone.lastTimings().normals_ms);
      alone_total.push_back(alone.lastTimings().total_ms);
      pair_normals.push_back(pair.lastTimings().normals_ms);
      pair_total.push_back(pair.lastTimings().total_ms);
    }
  std::printf("  measurement_threads 1 / 2, in turn: normals %.3f / %.3f ms, total %.3f / %.3f ms\n", median(alone_normals),
              median(pair_normals), median(alone_total), median(pair_total));
  std::vector<double> intrinsics_ms;
  for (int f = 0; f < frames; ++f)
  {
    const auto start = Clock::now();
    const PinholeIntrinsics k = estimateIntrinsics(rendered[f].view());
    intrinsics_ms.push_back(msSince(start));
    if (!k.valid()) std::printf("  no projection fitted to frame %d\n", f);
  }
  std::printf("  of the normals: the projection fitted to the cloud %.3f ms\n", median(intrinsics_ms));
  benchEigenSolvers(rendered);
  benchBlockSums(rendered);
}

// Real Kinect frames, a still camera: each file five times into one map; PCL's methods once.
bool benchRealFrames(const std::vector<std::string>& paths)
{
  PlaneDetector real{cameraFrameDefaults()};
  std::vector<double> ours_ms, labels_ms, ransac_ms, organized_ms;
  std::vector<int> labels;
  size_t ours_planes = 0, ransac_planes = 0, organized_planes = 0;
  for (int rep = 0; rep < 5; ++rep)
    for (size_t i = 0; i < paths.size(); ++i)
    {
      pcl::PCLPointCloud2 blob;
      std::string error;
      CloudView view;
      std::vector<float> converted;
      if (!loadPcd(paths[i], blob, &error) || !makeCloudView(layoutOf(blob), view, converted, &error) ||
          !real.processFrame(view, Eigen::Isometry3d::Identity(), rep * paths.size() + i, &error))
      {
        std::fprintf(stderr, "%s: %s\n", paths[i].c_str(), error.c_str());
        return false;
      }
      ours_ms.push_back(real.lastTimings().total_ms);
      ours_planes = real.planes().size();
      const auto labels_start = Clock::now();
      real.labelPixels(view, labels);
      labels_ms.push_back(msSince(labels_start));
      if (rep > 0) continue;
      auto cloud = toPclCloud(view);
      auto t = Clock::now();
      ransac_planes = pclRansacPlanes(cloud, 500, 0.02, 2000).size();
      ransac_ms.push_back(msSince(t));
      t = Clock::now();
      organized_planes = pclOrganizedPlanes(cloud, 2000).size();
      organized_ms.push_back(msSince(t));
    }
  std::printf("real Kinect frames (%zu PCD files, still camera): median ms per frame and planes found\n", paths.size());
  std::printf("  %-34s %8.2f ms  %zu planes in the map\n", "hough_plane_detector", median(ours_ms), ours_planes);
  std::printf("  %-34s %8.2f ms  (~inliers and ~segmented_cloud, only while subscribed)\n",
              "  of ours after the frame: pixel labels", median(labels_ms));
  std::printf("  %-34s %8.2f ms  %zu planes (last frame)\n", "PCL RANSAC (2 cm, 500 it, LSQ)", median(ransac_ms), ransac_planes);
  std::printf("  %-34s %8.2f ms  %zu planes (last frame)\n", "PCL OrganizedMultiPlaneSegm.", median(organized_ms),
              organized_planes);
  std::printf("  speed-up: %.1fx vs PCL RANSAC, %.1fx vs PCL organized segmentation\n", median(ransac_ms) / median(ours_ms),
              median(organized_ms) / median(ours_ms));
  for (const auto& p : real.planes())
    std::printf("    plane %d: n = (%+.3f %+.3f %+.3f), d = %+.3f, support %d\n", p.id, p.normal.x(), p.normal.y(),
                p.normal.z(), p.d, p.support);
  return true;
}
}  // namespace

int main(int argc, char** argv)
{
  const int frames = 40;
  std::printf("hough_plane_detector benchmark: 640 x 480 frames, default parameters (%d measurement threads: a\n"
              "frame's blocks and windows shared out, two pairs of stages side by side, the rest on one; PCL's\n"
              "methods on one)\n\n",
              DetectorParams().measurement_threads);
  SceneRenderer renderer(makeOfficeRoom());
  KinectNoise noise;
  noise.coefficient = 1.0;
  const auto poses = roomTour(frames);
  std::vector<RenderedFrame> rendered;
  for (int f = 0; f < frames; ++f) rendered.push_back(renderer.render(poses[f], noise, 500 + f));

  PlaneDetector detector{DetectorParams()};
  const MethodStats ours = benchStages(renderer, rendered, detector);
  benchVariants(rendered);
  const MemoryReport mem = detector.memory();
  std::printf("Hough space (resolution 1024): %.2f MB in %zu chunks = %.3f %% of the dense %.0f MB array "
              "(%.4f %% of a 1024^3 float array)\n\n",
              mem.global_bytes / 1e6, mem.global_chunks, 100.0 * mem.global_bytes / mem.dense_bytes, mem.dense_bytes / 1e6,
              100.0 * mem.global_bytes / (1024.0 * 1024.0 * 1024.0 * 4.0));

  // Comparators on every 4th frame (RANSAC is slow), in the same process.
  MethodStats ransac, organized;
  for (int f = 0; f < frames; f += 4) runComparators(rendered[f], renderer.truePlanes(), 500, 0.02, 2000, ransac, organized);
  std::printf("accuracy and time on the rendered frames (planes with >= 2000 visible points):\n");
  std::printf("  %-34s %8s %8s %8s   %-6s   %-6s   %-7s   %s\n", "method", "median", "p10", "p90", "E_ang", "E_d",
              "found", "false/frame");
  printStats(ours, "hough_plane_detector (map)");
  printStats(ransac, "PCL RANSAC (2 cm, 500 it, LSQ)");
  printStats(organized, "PCL OrganizedMultiPlaneSegm.");
  std::printf("  speed-up: %.1fx vs PCL RANSAC, %.1fx vs PCL organized segmentation\n\n",
              median(ransac.ms) / median(ours.ms), median(organized.ms) / median(ours.ms));
  if (argc > 1 && !benchRealFrames(std::vector<std::string>(argv + 1, argv + argc))) return 1;
  return 0;
}
