// The paper's section 4 regenerated from this code: Hough-space memory against noise (Fig. 6),
// accuracy against noise and resolution (Fig. 7), stability on a wall approach (Fig. 8), accuracy
// and detection on Kinect-like room sequences (Table 3) and time per frame (4.6.4), each with
// PCL RANSAC and PCL OrganizedMultiPlaneSegmentation measured on the same frames in this process.
// Writes OUT_DIR/RESULTS.md and the gnuplot data files OUT_DIR/results/*.dat, which
// scripts/evaluate.sh plots into OUT_DIR/results/*.png.
// Usage: evaluate_paper OUT_DIR [--quick] [--osd OSD_LEARN_DIR] [FRAME.pcd ...]
#include <chrono>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <pcl/PCLPointCloud2.h>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "hough_plane_detector/tools/input_sources.h"
#include "hough_plane_detector/sim/random_scene.h"
#include "osd_learn.h"
#include "pcl_comparators.h"
#include "stopwatch.h"

using namespace hough_plane_detector;

namespace
{
constexpr int kMinVisiblePoints = 2000;  // planes smaller in a frame are neither expected nor counted
constexpr int kWarmupFrames = 3;         // our map needs global_threshold frames before it reports
const double kNoiseLevels[] = {0.0, 0.3, 1.0, 4.0};
const int kResolutions[] = {512, 1024, 2048};

// The paper tuned RANSAC's inlier threshold to the noise: 0.01 m on clean data up to 0.05 m.
double ransacThreshold(double noise)
{
  if (noise <= 0.0) return 0.01;
  if (noise <= 0.5) return 0.02;
  if (noise <= 1.0) return 0.03;
  return 0.05;
}

// Our only noise-dependent knob: the C of eq. 11 the planarity test expects.
DetectorParams paramsFor(double noise, int resolution)
{
  DetectorParams p;
  p.resolution = resolution;
  p.sensor_noise = std::max(1.0, noise);
  return p;
}

// Fig. 6-8 as the paper ran them: its thinning (paper 3.7) instead of the default evidence.
DetectorParams paperParamsFor(double noise, int resolution)
{
  DetectorParams p = paramsFor(noise, resolution);
  p.forgetting = kForgetByThinning;
  return p;
}

struct Comparators
{
  MethodStats ransac, organized;
  // Runs both PCL methods on one frame and scores them against the scene's truth.
  void run(const RenderedFrame& frame, const std::vector<TruePlane>& truth, int ransac_iterations, double threshold)
  {
    const auto cloud = toPclCloud(frame.view());
    auto t = Clock::now();
    const auto r = pclRansacPlanes(cloud, ransac_iterations, threshold, kMinVisiblePoints);
    ransac.ms.push_back(msSince(t));
    ransac.add(evaluateFrame(truth, frame.visible_points, kMinVisiblePoints, planesToWorld(r, frame.camera_to_world)));
    t = Clock::now();
    const auto o = pclOrganizedPlanes(cloud, kMinVisiblePoints);
    organized.ms.push_back(msSince(t));
    organized.add(
        evaluateFrame(truth, frame.visible_points, kMinVisiblePoints, planesToWorld(o, frame.camera_to_world)));
  }
};

std::string fmt(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string fmt(const char* format, ...)
{
  char buffer[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

std::string meanStd(const std::vector<double>& v, const char* number_format)
{
  if (v.empty()) return "-";
  return fmt(number_format, mean(v)) + " +- " + fmt(number_format, standardDeviation(v));
}

std::string accuracyRow(const std::string& label, const MethodStats& s)
{
  return fmt("| %s | %s | %s | %.1f %% (%d/%d) | %.2f | %d |\n", label.c_str(), meanStd(s.angle, "%.4f").c_str(),
             meanStd(s.d, "%.4f").c_str(), s.detectionPercent(), s.detected, s.visible, s.falsePerFrame(), s.frames);
}

struct Report
{
  std::string out_dir;
  bool quick = false;
  std::ostringstream md;
  std::vector<std::string> verdicts;  // one line per target or comparison, met or not

  void verdict(bool met, const std::string& what)
  {
    verdicts.push_back(std::string(met ? "- met: " : "- **NOT met**: ") + what);
  }
  std::ofstream data(const std::string& name) const { return std::ofstream(out_dir + "/results/" + name); }
};

std::vector<RenderedFrame> renderSequence(const SceneRenderer& renderer, const std::vector<Eigen::Isometry3d>& poses,
                                          double noise, uint32_t seed)
{
  KinectNoise kinect;
  kinect.coefficient = noise;
  std::vector<RenderedFrame> frames;
  for (size_t f = 0; f < poses.size(); ++f) frames.push_back(renderer.render(poses[f], kinect, seed + f));
  return frames;
}

// Figures 6 and 7: the office tour at four noise levels; our detector at three resolutions on
// every frame, PCL's methods on every `stride`-th frame; all scored on those same frames.
void noiseExperiments(Report& report)
{
  const int frames = report.quick ? 16 : 48;
  const int stride = report.quick ? 8 : 4;
  const int ransac_iterations = 10000;
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(frames);
  auto memory_file = report.data("fig6_memory.dat");
  auto accuracy_file = report.data("fig7_accuracy.dat");
  memory_file << "# frame, Hough-space MB at resolution 1024 for C = 0, 0.3, 1.0, 4.0, then the dense array's MB\n";
  accuracy_file << "# C, then E_angle mean, E_angle std, E_d mean, E_d std for: hough512 hough1024 hough2048 ransac "
                   "organized\n";
  std::vector<std::vector<double>> memory_mb(frames);
  double dense_mb = 0;
  std::string table = "| C | method | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  std::string memory_table = "| C | Hough space after the run (MB) | peak (MB) | chunks | share of the dense array |\n"
                             "|---|---|---|---|---|\n";
  for (double noise : kNoiseLevels)
  {
    std::fprintf(stderr, "  noise C = %.1f: rendering %d frames\n", noise, frames);
    const auto rendered = renderSequence(renderer, poses, noise, 7000);
    std::vector<MethodStats> ours(3);
    for (int r = 0; r < 3; ++r)
    {
      PlaneDetector detector(paperParamsFor(noise, kResolutions[r]));
      double peak_mb = 0;
      for (int f = 0; f < frames; ++f)
      {
        detector.processFrame(rendered[f].view(), rendered[f].camera_to_world, 0.1 * f);
        ours[r].ms.push_back(detector.lastTimings().total_ms);
        if (kResolutions[r] == 1024)
        {
          const MemoryReport mem = detector.memory();
          memory_mb[f].push_back(mem.global_bytes / 1e6);
          peak_mb = std::max(peak_mb, mem.global_bytes / 1e6);
          dense_mb = mem.dense_bytes / 1e6;
          if (f == frames - 1)
            memory_table += fmt("| %.1f | %.2f | %.2f | %zu | %.3f %% |\n", noise, mem.global_bytes / 1e6, peak_mb,
                                mem.global_chunks, 100.0 * mem.global_bytes / mem.dense_bytes);
        }
        if (f >= kWarmupFrames && (f - kWarmupFrames) % stride == 0)
          ours[r].add(evaluateFrame(renderer.truePlanes(), rendered[f].visible_points, kMinVisiblePoints,
                                    evaluatedPlanes(detector.planes())));
      }
    }
    Comparators pcl;
    for (int f = kWarmupFrames; f < frames; f += stride)
    {
      std::fprintf(stderr, "    PCL methods on frame %d\n", f);
      pcl.run(rendered[f], renderer.truePlanes(), ransac_iterations, ransacThreshold(noise));
    }
    accuracy_file << noise;
    for (const MethodStats* s : {&ours[0], &ours[1], &ours[2], &pcl.ransac, &pcl.organized})
    {
      // No matched plane: no error to plot (not an error of zero).
      const double nan = std::numeric_limits<double>::quiet_NaN();
      accuracy_file << ' ' << (s->angle.empty() ? nan : mean(s->angle)) << ' ' << standardDeviation(s->angle) << ' '
                    << (s->d.empty() ? nan : mean(s->d)) << ' ' << standardDeviation(s->d);
    }
    accuracy_file << '\n';
    for (int r = 0; r < 3; ++r)
      table += fmt("| %.1f ", noise) + accuracyRow(fmt("Hough %d", kResolutions[r]), ours[r]);
    table += fmt("| %.1f ", noise) +
             accuracyRow(fmt("PCL RANSAC (%.2f m, %d it)", ransacThreshold(noise), ransac_iterations), pcl.ransac);
    table += fmt("| %.1f ", noise) + accuracyRow("PCL OMPS", pcl.organized);
    const MethodStats& best = ours[1];
    report.verdict(mean(best.angle) <= mean(pcl.ransac.angle),
                   fmt("Fig. 7, C = %.1f: Hough 1024 E_angle %.4f rad vs RANSAC %.4f", noise, mean(best.angle),
                       mean(pcl.ransac.angle)));
    report.verdict(mean(best.d) <= mean(pcl.ransac.d), fmt("Fig. 7, C = %.1f: Hough 1024 E_d %.4f m vs RANSAC %.4f",
                                                           noise, mean(best.d), mean(pcl.ransac.d)));
    report.verdict(best.detectionPercent() >= pcl.ransac.detectionPercent(),
                   fmt("Fig. 7, C = %.1f: Hough 1024 detects %.1f %% vs RANSAC %.1f %%", noise,
                       best.detectionPercent(), pcl.ransac.detectionPercent()));
  }
  for (int f = 0; f < frames; ++f)
  {
    memory_file << f;
    for (double mb : memory_mb[f]) memory_file << ' ' << mb;
    memory_file << ' ' << dense_mb << '\n';
  }
  report.md << "## Fig. 6: Hough-space memory against noise\n\n"
            << fmt("The office tour (%d frames, one turn), resolution 1024, after every frame. The dense 1024-grid "
                   "array would take %.0f MB. PCL's methods keep no accumulator, so they have no counterpart here.\n\n",
                   frames, dense_mb)
            << memory_table << "\n![Fig. 6](results/fig6_memory.png)\n\n";
  report.md << "## Fig. 7: accuracy against noise and resolution\n\n"
            << fmt("The same office tour at each noise level C. Our detector runs on every frame and its map is "
                   "scored on every %d-th frame from frame %d; PCL RANSAC (iterative SACSegmentation, least-squares "
                   "refinement, %d iterations per plane, inlier threshold by noise as in the paper) and PCL OMPS run "
                   "on exactly those frames. Planes with at least %d visible points count; E_angle and E_d are over "
                   "matched planes, mean +- standard deviation.\n\n",
                   stride, kWarmupFrames, ransac_iterations, kMinVisiblePoints)
            << table << "\n![Fig. 7](results/fig7_accuracy.png)\n\n";
}

// Figure 8: a camera driving at a wall from 5 m to 0.8 m; each method's wall per frame.
void wallApproachExperiment(Report& report)
{
  const int frames = report.quick ? 12 : 50;
  const double noise = 0.5, wall_x = 3.0;
  const int ransac_iterations = 10000;
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = wallApproach(frames, wall_x, 5.0, 0.8);
  const auto rendered = renderSequence(renderer, poses, noise, 9000);
  PlaneDetector detector(paperParamsFor(noise, 1024));
  const Eigen::Vector3d wall_normal = Eigen::Vector3d::UnitX();
  // Distance from the camera to the detected plane nearest the wall (within 0.1 rad and 0.5 m).
  auto wallDistance = [&](const std::vector<EvaluatedPlane>& planes, const Eigen::Vector3d& eye) {
    double best = std::numeric_limits<double>::quiet_NaN(), best_error = 0.5;
    for (const auto& p : planes)
    {
      if (angleError(p.normal, wall_normal) > 0.1) continue;
      const double sign = p.normal.dot(wall_normal) >= 0 ? 1.0 : -1.0;
      const double distance = -(sign * p.normal.dot(eye) + sign * p.d);  // wall ahead: n.eye + d < 0
      const double true_distance = wall_x - eye.x();
      if (std::abs(distance - true_distance) < best_error)
      {
        best_error = std::abs(distance - true_distance);
        best = distance;
      }
    }
    return best;
  };
  auto file = report.data("fig8_wall.dat");
  file << "# frame, true distance to the wall (m), detected distance: hough1024 ransac organized (nan = not found)\n";
  std::vector<double> errors[3];
  int found[3] = {0, 0, 0};
  for (int f = 0; f < frames; ++f)
  {
    std::fprintf(stderr, "    wall approach frame %d\n", f);
    const Eigen::Vector3d eye = rendered[f].camera_to_world.translation();
    detector.processFrame(rendered[f].view(), rendered[f].camera_to_world, 0.1 * f);
    const auto cloud = toPclCloud(rendered[f].view());
    const double distances[3] = {
        wallDistance(evaluatedPlanes(detector.planes()), eye),
        wallDistance(planesToWorld(pclRansacPlanes(cloud, ransac_iterations, ransacThreshold(noise), kMinVisiblePoints),
                                   rendered[f].camera_to_world),
                     eye),
        wallDistance(planesToWorld(pclOrganizedPlanes(cloud, kMinVisiblePoints), rendered[f].camera_to_world), eye)};
    const double truth = wall_x - eye.x();
    file << f << ' ' << truth;
    for (int m = 0; m < 3; ++m)
    {
      file << ' ' << distances[m];
      if (std::isnan(distances[m])) continue;
      ++found[m];
      errors[m].push_back(distances[m] - truth);
    }
    file << '\n';
  }
  const std::string names[3] = {"Hough 1024 (map)",
                                fmt("PCL RANSAC (%.2f m, %d it)", ransacThreshold(noise), ransac_iterations), "PCL OMPS"};
  report.md << "## Fig. 8: stability while approaching a wall\n\n"
            << fmt("A camera drives at the office's east wall from 5.0 m to 0.8 m in %d frames (C = %.1f). Per frame, "
                   "each method's plane nearest the wall (within 0.1 rad and 0.5 m) gives the distance to the wall; "
                   "error = detected - true.\n\n",
                   frames, noise)
            << "| method | frames with the wall | mean error (m) | std of the error (m) | worst error (m) |\n"
               "|---|---|---|---|---|\n";
  for (int m = 0; m < 3; ++m)
  {
    double worst = 0;
    for (double e : errors[m]) worst = std::max(worst, std::abs(e));
    report.md << fmt("| %s | %d / %d | %+.4f | %.4f | %.4f |\n", names[m].c_str(), found[m], frames, mean(errors[m]),
                     standardDeviation(errors[m]), worst);
  }
  report.md << "\n![Fig. 8](results/fig8_wall.png)\n\n";
  report.verdict(standardDeviation(errors[0]) <= standardDeviation(errors[1]) / 3.0,
                 fmt("Fig. 8: std of the wall's error %.4f m is at most a third of RANSAC's %.4f m",
                     standardDeviation(errors[0]), standardDeviation(errors[1])));
  report.verdict(found[0] >= found[1], fmt("Fig. 8: wall found in %d frames vs RANSAC's %d", found[0], found[1]));
}

// Why our detector missed a visible true plane in a frame: the fate of the local peak that
// matches it, or no peak at all, or a per-frame plane the map has not reported yet.
std::string missCause(const PlaneDetector& detector, const TruePlane& truth)
{
  const MatchTolerance tolerance;
  const PlaneCandidate* best = nullptr;
  double best_cost = 0.0;
  for (const PlaneCandidate& c : detector.lastCandidates())
  {
    const double ea = angleError(c.normal, truth.normal), ed = distanceError(c.normal, c.d, truth.normal, truth.d);
    const double cost = ea / tolerance.angle + ed / tolerance.distance;
    if (ea <= tolerance.angle && ed <= tolerance.distance && (!best || cost < best_cost))
    {
      best = &c;
      best_cost = cost;
    }
  }
  if (!best) return "no Hough peak";
  if (best->verdict == CandidateVerdict::kAccepted) return "seen, not yet in the map";
  return std::string(toString(best->verdict)) + (best->parallel_search ? " (parallel search)" : "");
}

struct MissTally
{
  std::map<int, int> visible_frames;                        // per true plane
  std::map<int, std::map<std::string, int>> ours_causes;  // per true plane: cause -> frames
};

// Table 3's losses, per plane: every plane some frame showed and our map missed, with the
// frames each method missed it and why ours did.
std::string missTable(const char* scene, const std::vector<TruePlane>& truth, const MissTally& tally,
                      const MethodStats& ransac, const MethodStats& organized)
{
  std::string rows;
  for (const auto& [plane, causes] : tally.ours_causes)
  {
    int ours = 0;
    std::string why;
    for (const auto& [cause, frames] : causes)
    {
      ours += frames;
      why += (why.empty() ? "" : ", ") + fmt("%s %d", cause.c_str(), frames);
    }
    auto missedBy = [plane = plane](const MethodStats& s) {
      const auto it = s.missed_by_plane.find(plane);
      return it == s.missed_by_plane.end() ? 0 : it->second;
    };
    rows += fmt("| %s | %s | %d | %d (%s) | %d | %d |\n", scene, truth[plane].name.c_str(),
                tally.visible_frames.at(plane), ours, why.c_str(), missedBy(ransac), missedBy(organized));
  }
  return rows;
}

struct NamedScene
{
  const char* name;
  Scene scene;
};

std::vector<NamedScene> tableThreeScenes()
{
  return {{"office (table, cabinet, shelf, pillar, ball)", makeOfficeRoom()},
          {"hall (ramp, stairs, recessed door, pillar, ball)", makeRampStairsHall()},
          {"lab (desks, cabinets, crate, bins, balls)", makeClutteredLab()}};
}

constexpr double kRoomNoise = 1.0;
constexpr int kRoomRansacIterations = 500;

struct TourResult
{
  std::vector<TruePlane> truth;  // the scene's
  MethodStats ours;
  Comparators pcl;
  MissTally tally;
};

// Our map through a tour of one scene at C = 1.0, scored on every stride-th frame from
// kWarmupFrames; PCL's methods on exactly those frames when with_pcl. Misses of ours are
// tallied by cause into `causes`.
TourResult runTour(const Scene& scene, const std::vector<Eigen::Isometry3d>& poses, uint32_t seed, int stride,
                   bool with_pcl, std::map<std::string, int>& causes, int region_growing = DetectorParams().region_growing,
                   int forgetting = DetectorParams().forgetting)
{
  SceneRenderer renderer(scene);
  const auto rendered = renderSequence(renderer, poses, kRoomNoise, seed);
  DetectorParams params = paramsFor(kRoomNoise, 1024);
  params.region_growing = region_growing;
  params.forgetting = forgetting;
  PlaneDetector detector(params);
  TourResult result;
  result.truth = renderer.truePlanes();
  const auto& truth = result.truth;
  for (size_t f = 0; f < rendered.size(); ++f)
  {
    detector.processFrame(rendered[f].view(), rendered[f].camera_to_world, 0.1 * f);
    result.ours.ms.push_back(detector.lastTimings().total_ms);
    if (static_cast<int>(f) < kWarmupFrames || (static_cast<int>(f) - kWarmupFrames) % stride != 0) continue;
    const FrameMetrics metrics = evaluateFrame(truth, rendered[f].visible_points, kMinVisiblePoints, evaluatedPlanes(detector.planes()));
    result.ours.add(metrics);
    for (size_t t = 0; t < truth.size(); ++t)
      if (rendered[f].visible_points[t] >= kMinVisiblePoints) ++result.tally.visible_frames[static_cast<int>(t)];
    for (int t : metrics.missed)
    {
      const std::string cause = missCause(detector, truth[t]);
      ++result.tally.ours_causes[t][cause];
      ++causes[cause];
    }
    if (with_pcl) result.pcl.run(rendered[f], truth, kRoomRansacIterations, ransacThreshold(kRoomNoise));
  }
  return result;
}

// Table 3 and 4.6.4: room tours at C = 1.0 through three scenes; timing from the same runs (one
// thread, one method at a time).
void roomExperiments(Report& report)
{
  const int frames = report.quick ? 16 : 60;
  const int stride = report.quick ? 8 : 3;
  const double noise = kRoomNoise;
  const int ransac_iterations = kRoomRansacIterations;
  const double threshold = ransacThreshold(noise);
  MethodStats all_ours, all_ransac, all_organized;
  std::string table = "| scene | method | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  std::string misses;
  std::map<std::string, int> causes;  // over all scenes
  for (const auto& named : tableThreeScenes())
  {
    std::fprintf(stderr, "  Table 3: %s\n", named.name);
    const TourResult tour = runTour(named.scene, roomTour(frames), 11000, stride, true, causes);
    const MethodStats& ours = tour.ours;
    const Comparators& pcl = tour.pcl;
    misses += missTable(named.name, tour.truth, tour.tally, pcl.ransac, pcl.organized);
    table += fmt("| %s ", named.name) + accuracyRow("Hough 1024 (map)", ours);
    table += fmt("| %s ", named.name) + accuracyRow(fmt("PCL RANSAC (%.2f m, %d it)", threshold, ransac_iterations), pcl.ransac);
    table += fmt("| %s ", named.name) + accuracyRow("PCL OMPS", pcl.organized);
    all_ours.merge(ours);
    all_ransac.merge(pcl.ransac);
    all_organized.merge(pcl.organized);
  }
  table += "| **all scenes** " + accuracyRow("**Hough 1024 (map)**", all_ours);
  table += "| **all scenes** " + accuracyRow(fmt("PCL RANSAC (%.2f m, %d it)", threshold, ransac_iterations), all_ransac);
  table += "| **all scenes** " + accuracyRow("PCL OMPS", all_organized);
  report.md << "## Table 3: Kinect-like room sequences (C = 1.0)\n\n"
            << fmt("Each scene is toured in %d frames (a camera 1 m high circling the room centre, 20 deg down) with "
                   "eq. 11 noise at C = %.1f and 1/8-pixel disparity quantization. Our map is scored on every %d-th "
                   "frame from frame %d, the PCL methods run on exactly those frames. Detected = true planes with at "
                   "least %d visible points matched by a detection (within 0.08 rad and 0.07 m, one to one); false = "
                   "detections matching no plane of the scene.\n\n",
                   frames, noise, stride, kWarmupFrames, kMinVisiblePoints)
            << table << '\n';
  std::string cause_list;
  for (const auto& [cause, frames] : causes) cause_list += fmt("%s%s: %d", cause_list.empty() ? "" : "; ", cause.c_str(), frames);
  report.md << "### Where our map misses planes (Table 3 frames)\n\n"
            << "Every plane a scored frame showed with enough points and our map did not match, with the frames "
               "each method missed it. Why ours did, per frame: the fate of the local Hough peak or the parallel "
               "search's cluster that matches the plane (`PlaneDetector::lastCandidates()`), \"no Hough peak\" "
               "when neither a window vote above local_threshold nor a cluster of free blocks along a known normal "
               "came near it, \"seen, not yet in the map\" when the frame accepted it but the global space has "
               "not reached global_threshold.\n\n"
            << "Misses by cause, all scenes: " << (cause_list.empty() ? "none" : cause_list) << ".\n\n"
            << "| scene | plane | frames visible | ours missed (why) | RANSAC missed | OMPS missed |\n"
               "|---|---|---|---|---|---|\n"
            << misses << '\n';
  report.verdict(mean(all_ours.angle) <= 0.01, fmt("Table 3: E_angle %.4f rad <= 0.01", mean(all_ours.angle)));
  report.verdict(mean(all_ours.d) <= 0.01, fmt("Table 3: E_d %.4f m <= 0.01", mean(all_ours.d)));
  report.verdict(all_ours.detectionPercent() >= 95.0,
                 fmt("Table 3: detection %.1f %% >= 95 %%", all_ours.detectionPercent()));
  report.verdict(all_ours.falsePerFrame() < 0.05,
                 fmt("Table 3: %.3f false planes per frame < 0.05", all_ours.falsePerFrame()));
  for (const auto& [name, other] : {std::pair<const char*, const MethodStats*>{"RANSAC", &all_ransac},
                                    std::pair<const char*, const MethodStats*>{"OMPS", &all_organized}})
  {
    report.verdict(mean(all_ours.angle) < mean(other->angle),
                   fmt("Table 3: E_angle better than %s (%.4f vs %.4f rad)", name, mean(all_ours.angle), mean(other->angle)));
    report.verdict(mean(all_ours.d) < mean(other->d),
                   fmt("Table 3: E_d better than %s (%.4f vs %.4f m)", name, mean(all_ours.d), mean(other->d)));
    report.verdict(all_ours.detectionPercent() >= other->detectionPercent(),
                   fmt("Table 3: detection better than %s (%.1f vs %.1f %%)", name, all_ours.detectionPercent(),
                       other->detectionPercent()));
    report.verdict(all_ours.falsePerFrame() <= other->falsePerFrame(),
                   fmt("Table 3: false planes per frame no more than %s (%.3f vs %.3f)", name,
                       all_ours.falsePerFrame(), other->falsePerFrame()));
  }

  // Timing from the same runs: every frame for ours, the scored frames for PCL's methods.
  auto file = report.data("timing.dat");
  file << "# method, median ms, p10, p90, mean, std\n";
  report.md << "## Time per frame (4.6.4)\n\n"
            << "From the Table 3 runs above: one thread, one method at a time, 640 x 480 frames, on this machine.\n\n"
            << "| method | median (ms) | p10 | p90 | mean +- std | frames | ours faster by (median) |\n"
               "|---|---|---|---|---|---|---|\n";
  const std::pair<const char*, const MethodStats*> methods[] = {
      {"Hough_1024", &all_ours}, {"PCL_RANSAC", &all_ransac}, {"PCL_OMPS", &all_organized}};
  for (const auto& [name, s] : methods)
  {
    file << '"' << name << "\" " << median(s->ms) << ' ' << percentile(s->ms, 0.1) << ' ' << percentile(s->ms, 0.9)
         << ' ' << mean(s->ms) << ' ' << standardDeviation(s->ms) << '\n';
    report.md << fmt("| %s | %.2f | %.2f | %.2f | %.2f +- %.2f | %zu | %.1fx |\n", name, median(s->ms),
                     percentile(s->ms, 0.1), percentile(s->ms, 0.9), mean(s->ms), standardDeviation(s->ms),
                     s->ms.size(), median(s->ms) / median(all_ours.ms));
  }
  report.md << "\n![time per frame](results/timing.png)\n\n";
  for (const auto& [name, other] : {methods[1], methods[2]})
    report.verdict(median(other->ms) >= 10.0 * median(all_ours.ms),
                   fmt("timing: at least 10x faster than %s (%.1fx)", name, median(other->ms) / median(all_ours.ms)));
}

// Table 3's scenes seen along other paths and with other noise: the detector's thresholds were
// chosen while looking at Table 3's tours, so these show how much of its result carries over.
void otherToursExperiment(Report& report)
{
  struct Tour
  {
    const char* name;
    int frames;
    Eigen::Vector3d centre;
    double radius;
    uint32_t seed;
  };
  // The first five were used while developing the snap to a known normal (to refuse variants
  // that made false planes there); the last two were first run after the detector was fixed.
  const Tour tours[] = {{"A: Table 3's path, noise seed 5000", 60, {0, 0, 1.0}, 0.5, 5000},
                        {"B: Table 3's path, noise seed 77000", 60, {0, 0, 1.0}, 0.5, 77000},
                        {"C: 45 poses on Table 3's circle", 45, {0, 0, 1.0}, 0.5, 300},
                        {"D: circle of 0.7 m about (0.3, -0.2), 50 poses", 50, {0.3, -0.2, 1.0}, 0.7, 900},
                        {"E: circle of 0.4 m about (-0.4, 0.3), camera 1.3 m high, 40 poses", 40, {-0.4, 0.3, 1.3}, 0.4, 1700},
                        {"F: circle of 0.3 m about (0.5, 0.4), camera 1.1 m high, 55 poses", 55, {0.5, 0.4, 1.1}, 0.3, 2024},
                        {"G: circle of 0.6 m about (-0.2, -0.5), camera 0.9 m high, 48 poses", 48, {-0.2, -0.5, 0.9}, 0.6, 3131}};
  const size_t tour_count = report.quick ? 1 : sizeof(tours) / sizeof(tours[0]);
  const int stride = 3;
  std::string table = "| tour (all three scenes) | method | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  MethodStats all_ours, all_ransac, all_organized;
  std::map<std::string, int> causes;
  for (size_t i = 0; i < tour_count; ++i)
  {
    const Tour& tour = tours[i];
    std::fprintf(stderr, "  other tours: %s\n", tour.name);
    MethodStats ours, ransac, organized;
    for (const auto& named : tableThreeScenes())
    {
      const TourResult result =
          runTour(named.scene, roomTour(tour.frames, tour.centre, tour.radius), tour.seed, stride, !report.quick, causes);
      ours.merge(result.ours);
      ransac.merge(result.pcl.ransac);
      organized.merge(result.pcl.organized);
    }
    table += fmt("| %s ", tour.name) + accuracyRow("Hough 1024 (map)", ours);
    if (!report.quick)
    {
      table += fmt("| %s ", tour.name) + accuracyRow("PCL RANSAC", ransac);
      table += fmt("| %s ", tour.name) + accuracyRow("PCL OMPS", organized);
    }
    all_ours.merge(ours);
    all_ransac.merge(ransac);
    all_organized.merge(organized);
  }
  table += "| **all these tours** " + accuracyRow("**Hough 1024 (map)**", all_ours);
  if (!report.quick)
  {
    table += "| **all these tours** " + accuracyRow("PCL RANSAC", all_ransac);
    table += "| **all these tours** " + accuracyRow("PCL OMPS", all_organized);
  }
  std::string cause_list;
  for (const auto& [cause, frames] : causes) cause_list += fmt("%s%s: %d", cause_list.empty() ? "" : "; ", cause.c_str(), frames);
  report.md << "## Table 3's scenes along other paths\n\n"
            << "The detector's thresholds were chosen while looking at Table 3's tours (and the unit tests' "
               "scenes). These runs render the same three scenes with other noise seeds and along other "
               "camera paths, scored the same way (every 3rd frame from frame 3), so they show how much of "
               "Table 3 carries over to views the thresholds were not chosen on. Tours A-E were also looked at "
               "while the snap to a known normal was developed (variants that made false planes there were "
               "dropped); F and G were first run after the detector was fixed. Where ours misses: "
            << (cause_list.empty() ? "nothing" : cause_list) << ".\n\n"
            << table << '\n';
  report.verdict(all_ours.detectionPercent() >= 95.0 && all_ours.falsePerFrame() < 0.05,
                 fmt("other tours of Table 3's scenes: detection %.1f %% >= 95 %% and %.3f false planes per frame < 0.05",
                     all_ours.detectionPercent(), all_ours.falsePerFrame()));
}

// Table 3's tours (ours only): the default beside the paper's per-frame stage (region_growing 0)
// and beside the paper's thinning.
void stageAndForgettingTours(Report& report)
{
  const int frames = report.quick ? 16 : 60;
  const int stride = report.quick ? 8 : 3;
  std::map<std::string, int> causes;
  MethodStats windows, regions, thinning;
  std::string table = "| scene | per-frame stage | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  for (const auto& named : tableThreeScenes())
  {
    std::fprintf(stderr, "  windows' fit: %s\n", named.name);
    const TourResult w = runTour(named.scene, roomTour(frames), 11000, stride, false, causes, 0);
    const TourResult r = runTour(named.scene, roomTour(frames), 11000, stride, false, causes, 1);
    const TourResult t = runTour(named.scene, roomTour(frames), 11000, stride, false, causes, 1, kForgetByThinning);
    table += fmt("| %s ", named.name) + accuracyRow("block regions (default)", r.ours);
    table += fmt("| %s ", named.name) + accuracyRow("windows (region_growing 0)", w.ours);
    table += fmt("| %s ", named.name) + accuracyRow("forgetting by thinning (forgetting 0, the paper)", t.ours);
    thinning.merge(t.ours);
    windows.merge(w.ours);
    regions.merge(r.ours);
  }
  table += "| **all scenes** " + accuracyRow("block regions (default)", regions);
  table += "| **all scenes** " + accuracyRow("windows (region_growing 0)", windows);
  table += "| **all scenes** " + accuracyRow("forgetting by thinning (forgetting 0, the paper)", thinning);
  report.md << "## Table 3's tours: block regions against the paper's windows, thinning against evidence\n\n"
            << "The same tours and scoring as Table 3, ours only: the default per-frame stage (block regions "
               "grown from the Hough peaks) beside the paper's (each peak takes the windows that agree with it, "
               "`region_growing 0`), and the default map (forgetting by evidence: planes out of view keep their "
               "state, planes whose extent the frames contradict leave) beside the paper's thinning "
               "(`forgetting 0`: every cell loses thinning_rate per frame).\n\n"
            << table << '\n';
  report.verdict(regions.detectionPercent() >= windows.detectionPercent() && regions.falsePerFrame() <= windows.falsePerFrame(),
                 fmt("Table 3's tours: block regions detect %.1f %% (windows %.1f %%) with %.3f false planes per frame "
                     "(windows %.3f)",
                     regions.detectionPercent(), windows.detectionPercent(), regions.falsePerFrame(),
                     windows.falsePerFrame()));
}

// Procedural rooms (sim/random_scene.h): the held-out seeds decide, the tuning seeds are shown
// beside them. Ours only (defaults, ablations, the paper's windows), every 3rd frame from frame 3.
void randomSceneExperiment(Report& report)
{
  const int frames = report.quick ? 12 : 30;
  const size_t held_out_count = report.quick ? 5 : kHeldOutSeeds.size();
  const size_t tuning_count = report.quick ? 3 : kTuningSeeds.size();
  // The default and what each of its own rules adds (ablations), then the region stage.
  struct Variant
  {
    const char* name;
    std::function<void(DetectorParams&)> change;
  };
  const std::vector<Variant> variants = {
      {"**defaults (block regions)**", [](DetectorParams&) {}},
      {"no parallel search", [](DetectorParams& p) { p.parallel_support = 0; }},
      {"no snap", [](DetectorParams& p) { p.snap_angle = 0.0; }},
      {"forgetting by thinning (the paper)", [](DetectorParams& p) { p.forgetting = kForgetByThinning; }},
      {"windows (region_growing 0)", [](DetectorParams& p) { p.region_growing = 0; }},
  };
  std::vector<MethodStats> held_out(variants.size()), tuning(variants.size());
  std::string rows;
  auto runSeed = [&](uint32_t seed, std::vector<MethodStats>& set, bool row) {
    const RandomScene room = makeRandomScene(seed, frames);
    const SceneRenderer renderer(room.scene);
    std::vector<std::unique_ptr<PlaneDetector>> detectors;
    for (const Variant& variant : variants)
    {
      DetectorParams params = paramsFor(room.noise, 1024);
      variant.change(params);
      detectors.push_back(std::make_unique<PlaneDetector>(params));
    }
    std::vector<MethodStats> stats(variants.size());
    KinectNoise noise;
    noise.coefficient = room.noise;
    for (int f = 0; f < frames; ++f)
    {
      const RenderedFrame frame = renderer.render(room.poses[f], noise, seed * 1000 + f);
      for (auto& detector : detectors) detector->processFrame(frame.view(), frame.camera_to_world, 0.1 * f);
      if (f < kWarmupFrames || (f - kWarmupFrames) % 3 != 0) continue;
      for (size_t v = 0; v < variants.size(); ++v)
        stats[v].add(evaluateFrame(renderer.truePlanes(), frame.visible_points, kMinVisiblePoints, evaluatedPlanes(detectors[v]->planes())));
    }
    if (row)
      rows += fmt("| %u | %s | %.1f %% | %.2f | %.1f %% | %.2f |\n", seed, room.description.c_str(),
                  stats.front().detectionPercent(), stats.front().falsePerFrame(), stats.back().detectionPercent(),
                  stats.back().falsePerFrame());
    for (size_t v = 0; v < variants.size(); ++v) set[v].merge(stats[v]);
  };
  for (size_t i = 0; i < tuning_count; ++i)
  {
    std::fprintf(stderr, "  tuning seed %u\n", kTuningSeeds[i]);
    runSeed(kTuningSeeds[i], tuning, false);
  }
  for (size_t i = 0; i < held_out_count; ++i)
  {
    std::fprintf(stderr, "  held-out seed %u\n", kHeldOutSeeds[i]);
    runSeed(kHeldOutSeeds[i], held_out, true);
  }
  std::string table = "| seeds | detector | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  for (size_t v = 0; v < variants.size(); ++v)
    table += fmt("| %zu held-out ", held_out_count) + accuracyRow(variants[v].name, held_out[v]);
  for (size_t v = 0; v < variants.size(); ++v)
    table += fmt("| %zu tuning ", tuning_count) + accuracyRow(variants[v].name, tuning[v]);
  report.md << "## Procedural rooms: held-out seeds\n\n"
            << fmt("Rooms from `makeRandomScene` (src/sim/random_scene.cpp): random size (4-8 x 3.5-7 x 2.4-3.2 m) "
                   "and yaw; by chance stairs (rise 12-20 cm, run 25-35 cm), a ramp (5-20 deg), a ceiling sloping "
                   "20-45 deg, shelving with boards 30-40 cm apart, a door open 30-80 deg; always 1-2 tables, 2-5 boxes "
                   "at random yaw (some stacked), cylinders and balls; a camera circling at 0.8-1.6 m, 10-35 deg down; "
                   "eq. 11 noise with C drawn from 0.5-2 (the detector's sensor_noise = max(1, C)). %d frames a room, "
                   "scored every 3rd from frame %d as Table 3. The held-out seeds (101-120) were written down before "
                   "any threshold was chosen on these rooms and are reported only; tuning looks at seeds 901-908 "
                   "only. The rows without the parallel search and without the snap show what each of those rules "
                   "adds. Targets on the held-out seeds (C = 0.5-2 here, not C = 1 alone): >= 95 %% detected, <= "
                   "0.05 false planes per frame, E_angle <= 0.01 rad, E_d <= 1 cm.\n\n",
                   frames, kWarmupFrames)
            << table << "\n| held-out seed | room | defaults detected | false / frame | windows detected | "
                        "false / frame |\n|---|---|---|---|---|---|\n"
            << rows << '\n';
  const MethodStats& h = held_out.front();
  report.verdict(h.detectionPercent() >= 95.0 && h.falsePerFrame() <= 0.05 && mean(h.angle) <= 0.01 && mean(h.d) <= 0.01,
                 fmt("held-out procedural rooms (defaults): %.1f %% detected >= 95 %%, %.3f false planes per frame <= "
                     "0.05, E_angle %.4f rad, E_d %.4f m",
                     h.detectionPercent(), h.falsePerFrame(), mean(h.angle), mean(h.d)));
}

// ../shared/data/kinect-real: a still camera, no ground truth; time and planes found.
bool realFrames(Report& report, const std::vector<std::string>& paths)
{
  if (paths.empty()) return true;
  std::vector<double> ours_ms, ransac_ms, organized_ms;
  size_t ransac_planes = 0, organized_planes = 0;
  std::string pictures, found;
  // Each frame alone with the defaults: one frame is a complete answer.
  for (size_t i = 0; i < paths.size(); ++i)
  {
    pcl::PCLPointCloud2 blob;
    std::string error;
    CloudView view;
    std::vector<float> converted;
    if (!loadPcd(paths[i], blob, &error) || !makeCloudView(layoutOf(blob), view, converted, &error))
    {
      std::fprintf(stderr, "%s: %s\n", paths[i].c_str(), error.c_str());
      return false;
    }
    const std::string file = paths[i].substr(paths[i].find_last_of('/') + 1);
    PlaneDetector detector{DetectorParams()};
    if (!detector.processFrame(view, Eigen::Isometry3d::Identity(), 0.0, &error))
    {
      std::fprintf(stderr, "%s: %s\n", paths[i].c_str(), error.c_str());
      return false;
    }
    ours_ms.push_back(detector.lastTimings().total_ms);
    const std::string picture = fmt("kinect_real_%zu.png", i);
    if (writeSegmentedPicture(report.out_dir + "/results/" + picture, detector, view, &error))
      pictures += "![" + picture + "](results/" + picture + ") ";
    found += fmt("- %s: %zu planes:", file.c_str(), detector.planes().size());
    for (const DetectedPlane& p : detector.planes())
      found += fmt(" n (%.2f, %.2f, %.2f) d %.3f m, %d points;", p.normal.x(), p.normal.y(), p.normal.z(), p.d, p.support);
    found += "\n";
    const auto cloud = toPclCloud(view);
    auto t = Clock::now();
    ransac_planes = pclRansacPlanes(cloud, 500, 0.05, kMinVisiblePoints).size();
    ransac_ms.push_back(msSince(t));
    t = Clock::now();
    organized_planes = pclOrganizedPlanes(cloud, kMinVisiblePoints).size();
    organized_ms.push_back(msSince(t));
  }
  report.md << "## Real Kinect frames\n\n"
            << fmt("%zu organized frames from ../shared/data/kinect-real (PCL's test data; a still camera, no ground "
                   "truth, so no accuracy: a floor, a wall and boxes). Each frame alone with the defaults, camera "
                   "frame = world frame. RANSAC as the paper on real data (0.05 m, 500 iterations).\n\n",
                   paths.size())
            << "| method | median ms per frame | planes in the last frame |\n|---|---|---|\n"
            << fmt("| Hough 1024 (defaults) | %.2f | see below |\n", median(ours_ms))
            << fmt("| PCL RANSAC (0.05 m, 500 it) | %.2f | %zu |\n", median(ransac_ms), ransac_planes)
            << fmt("| PCL OMPS | %.2f | %zu |\n\n", median(organized_ms), organized_planes) << found << '\n'
            << "Segmented (plane colours; grey: on no plane; black: no return):\n\n"
            << pictures << "\n\n";
  return true;
}

// ../shared/data/osd-learn: real frames with annotated planes, with the defaults.
bool osdLearnFrames(Report& report, const std::string& dir)
{
  if (dir.empty()) return true;
  OsdResults results;
  std::string error;
  if (!evaluateOsdLearn(dir, DetectorParams(), true, report.out_dir + "/results", results, &error))
  {
    std::fprintf(stderr, "osd-learn: %s\n", error.c_str());
    return false;
  }
  const OsdMethodResult& ours = results.methods[0];
  report.md << "## Real frames with annotated planes (osd-learn)\n\n"
            << fmt("45 real 640 x 480 table-top frames of a structured-light camera with 190 annotated planes "
                   "(../shared/data/osd-learn: the table and every flat box face of 2,000+ points; learn33-44 hold cans "
                   "and mugs). Scored as its README says: a detection matches an entry within 0.06 rad and 3 cm; a "
                   "second detection of one entry is a duplicate; an unmatched detection is not necessarily false "
                   "(small faces and the background are not annotated). PCL with 1,500 points as minimum. These frames "
                   "are not held out: the block regions' noise terms, the curvature limit and the first-sight rule "
                   "were chosen while looking at them. Our detector with its defaults, each frame alone and given five "
                   "times (a still camera). Pixel labels (pictures, planes on cans) come from the accepted regions' "
                   "blocks, and from the 32 px windows for a map plane no region of the frame measured.\n\n")
            << osdLearnMarkdown(results, "results/");
  report.verdict(ours.foundPercent() >= 90.0 && ours.duplicates == 0 && ours.curved_planes == 0,
                 fmt("osd-learn, one frame: %.1f %% of the annotated planes >= 90 %%, %d duplicates, "
                     "%d planes on cans and mugs (target 0)",
                     ours.foundPercent(), ours.duplicates, ours.curved_planes));
  report.verdict(mean(ours.angle_errors) <= 0.01 && mean(ours.d_errors) <= 0.005,
                 fmt("osd-learn, one frame: E_angle %.4f rad <= 0.01, E_d %.4f m <= 0.005", mean(ours.angle_errors),
                     mean(ours.d_errors)));
  return true;
}
}  // namespace

int main(int argc, char** argv)
{
  Report report;
  std::vector<std::string> pcds;
  std::string osd_dir;
  for (int i = 1; i < argc; ++i)
  {
    if (std::strcmp(argv[i], "--quick") == 0)
      report.quick = true;
    else if (std::strcmp(argv[i], "--osd") == 0 && i + 1 < argc)
      osd_dir = argv[++i];
    else if (report.out_dir.empty())
      report.out_dir = argv[i];
    else
      pcds.push_back(argv[i]);
  }
  if (report.out_dir.empty())
  {
    std::fprintf(stderr, "usage: evaluate_paper OUT_DIR [--quick] [--osd OSD_LEARN_DIR] [FRAME.pcd ...]\n");
    return 2;
  }
  const auto start = Clock::now();
  std::fprintf(stderr, "Fig. 6 and 7: noise levels\n");
  noiseExperiments(report);
  std::fprintf(stderr, "Fig. 8: wall approach\n");
  wallApproachExperiment(report);
  std::fprintf(stderr, "Table 3 and timing: room tours\n");
  roomExperiments(report);
  std::fprintf(stderr, "Table 3's scenes along other paths\n");
  otherToursExperiment(report);
  if (!realFrames(report, pcds)) return 1;
  std::fprintf(stderr, "Procedural rooms: held-out seeds\n");
  randomSceneExperiment(report);
  std::fprintf(stderr, "Table 3's tours with the windows' fit\n");
  stageAndForgettingTours(report);
  std::fprintf(stderr, "osd-learn: real frames with annotated planes\n");
  if (!osdLearnFrames(report, osd_dir)) return 1;

  std::ofstream out(report.out_dir + "/RESULTS.md");
  out << "# Results: the paper's experiments, regenerated\n\n"
      << "Written by `make evaluate" << (report.quick ? " QUICK=1" : "")
      << "` (bench/evaluate_paper.cpp, plots by scripts/evaluate.sh with gnuplot); "
      << (report.quick ? "QUICK=1: short sequences and few comparator frames, for routine checks only. "
                       : "the full run. ")
      << fmt("Every number below comes from one run on this machine (%.0f s). Our detector runs with its defaults "
             "(resolution as stated, `sensor_noise` = max(1, C)), except that Fig. 6-8 use the paper's thinning "
             "(`forgetting 0`); the PCL methods get the same frames as PCL point clouds.\n\n",
             std::chrono::duration<double>(Clock::now() - start).count())
      << "## Targets and comparisons\n\n";
  for (const auto& line : report.verdicts) out << line << '\n';
  out << '\n' << report.md.str();
  std::fprintf(stderr, "wrote %s/RESULTS.md in %.0f s\n", report.out_dir.c_str(),
               std::chrono::duration<double>(Clock::now() - start).count());
  return 0;
}
