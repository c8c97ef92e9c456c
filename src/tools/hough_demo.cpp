// `make demo` without hardware: a simulated Kinect tours a room; the detected planes are
// printed next to the true ones with the accuracy metrics and ms per frame.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "hough_plane_detector/tools/cli_options.h"

using namespace hough_plane_detector;

namespace
{
// The map's planes, each beside the true plane nearest it (if within twice the match tolerance).
void printMap(const PlaneDetector& detector, const SceneRenderer& renderer, int frames)
{
  std::printf("\nplanes in the map after %d frames (world frame, n.p + d = 0):\n", frames);
  std::printf("  id  normal                      d        strength  support  | true plane            E_angle  E_d\n");
  for (const auto& p : detector.planes())
  {
    const TruePlane* best = nearestTruePlane(p.normal, p.d, renderer.truePlanes());
    std::printf("  %2d  (%+.3f %+.3f %+.3f)  %+7.3f  %8.2f  %7d  | ", p.id, p.normal.x(), p.normal.y(), p.normal.z(),
                p.d, p.strength, p.support);
    if (best)
      std::printf("%-20s  %.4f   %.4f\n", best->name.c_str(), angleError(p.normal, best->normal),
                  distanceError(p.normal, p.d, best->normal, best->d));
    else
      std::printf("(no true plane)\n");
  }
}
}  // namespace

int main(int argc, char** argv)
{
  namespace po = boost::program_options;
  int frames = 40;
  double noise = 1.0;
  std::string scene_name = "office";
  DetectorParams params;
  po::options_description demo("options"), detector_options("detector parameters"), hidden;
  demo.add_options()("help,h", "this help")
      ("frames", po::value(&frames)->value_name("N")->default_value(40)->notifier([](int n) {
        if (n < 1) throw po::error("--frames needs a positive integer, got " + std::to_string(n));
      }), "frames of the tour")
      ("noise", po::value(&noise)->value_name("C")->default_value(1.0)->notifier([](double c) {
        if (!(c >= 0.0)) throw po::error("--noise needs a number >= 0");
      }), "noise coefficient C of eq. 11")
      ("scene", po::value(&scene_name)->value_name("NAME")->default_value("office")->notifier([](const std::string& name) {
        if (name != "office" && name != "hall") throw po::error("--scene needs office or hall, got '" + name + "'");
      }), "office or hall");
  addDetectorParamOptions(params, detector_options, hidden);
  po::options_description all;
  all.add(demo).add(detector_options).add(hidden);
  po::variables_map values;
  std::string error;
  if (!parseCommandLine(argc, argv, all, po::positional_options_description(), values, &error))
  {
    std::fprintf(stderr, "hough_demo: %s\n", error.c_str());
    return 2;
  }
  if (values.count("help"))
  {
    std::cout << "usage: hough_demo [options]\n" << demo << detector_options;
    return 0;
  }
  std::string invalid;
  if (!params.validate(&invalid))
  {
    std::fprintf(stderr, "hough_demo: %s\n", invalid.c_str());
    return 2;
  }
  const Scene scene = scene_name == "hall" ? makeRampStairsHall() : makeOfficeRoom();
  SceneRenderer renderer(scene);
  PlaneDetector detector(params);
  KinectNoise kinect;
  kinect.coefficient = noise;
  std::vector<double> ms, angle_errors, d_errors;
  int visible = 0, detected = 0, false_total = 0;
  const int warmup = 3;
  std::printf("simulated Kinect, %s scene, noise C = %.2f, %d frames, resolution %d\n", scene_name.c_str(), noise,
              frames, params.resolution);
  std::printf("frame  ms     planes  visible  found  false\n");
  const auto poses = roomTour(frames);
  for (int f = 0; f < frames; ++f)
  {
    const RenderedFrame frame = renderer.render(poses[f], kinect, 1000 + f);
    std::string error;
    if (!detector.processFrame(frame.view(), frame.camera_to_world, 0.1 * f, &error))
    {
      std::fprintf(stderr, "frame %d: %s\n", f, error.c_str());
      return 1;
    }
    ms.push_back(detector.lastTimings().total_ms);
    const FrameMetrics m =
        evaluateFrame(renderer.truePlanes(), frame.visible_points, 2000, evaluatedPlanes(detector.planes()));
    const FrameStats& st = detector.lastStats();
    std::printf("%5d  %5.2f  %6zu  %7d  %5d  %5d   (windows %d, planar %d, cache cells %d, local peaks %d)\n", f,
                detector.lastTimings().total_ms, detector.planes().size(), m.visible, m.detected, m.false_detections,
                st.windows_valid, st.samples, st.cache_cells, st.local_peaks);
    if (f < warmup) continue;
    visible += m.visible;
    detected += m.detected;
    false_total += m.false_detections;
    angle_errors.insert(angle_errors.end(), m.angle_errors.begin(), m.angle_errors.end());
    d_errors.insert(d_errors.end(), m.d_errors.begin(), m.d_errors.end());
  }

  printMap(detector, renderer, frames);
  auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / v.size();
  };
  std::sort(ms.begin(), ms.end());
  const MemoryReport mem = detector.memory();
  std::printf("\nafter frame %d: E_angle %.4f rad, E_d %.4f m, detected %d of %d visible planes (%.1f %%), "
              "%.3f false planes per frame\n",
              warmup, mean(angle_errors), mean(d_errors), detected, visible, visible ? 100.0 * detected / visible : 0.0,
              static_cast<double>(false_total) / std::max(1, frames - warmup));
  std::printf("median %.2f ms per frame (%d frames); Hough space %.2f MB = %.3f %% of the dense %.0f MB\n",
              ms[ms.size() / 2], frames, mem.global_bytes / 1e6, 100.0 * mem.global_bytes / mem.dense_bytes,
              mem.dense_bytes / 1e6);
  return 0;
}
