// The rendered sets a change to the detector may be judged and tuned on, in about two and a half minutes
// (make tuning-check): the tuning and development seeds of the procedural rooms (the latter
// also at C = 1, where make evaluate's held-out verdict is made), the second development list at C = 1, Table 3's
// tours, its scenes along the other paths and Fig. 7's office at C = 4, each as one line with the
// same scoring as make evaluate (PCL's methods left out). The held-out seeds are not here on
// purpose: their figures come from make evaluate only, after a change is decided.
// With --osd, the annotated real frames of osd-learn too (one frame each, PCL left out).
// Each set's line is followed by its 95 % interval over its rooms; --per-room FILE keeps each
// room's counts, and a later run's --against FILE prints each set's effect paired by room.
// Usage: tuning_check [--sets LIST] [--osd DIR] [--causes] [--list] [--sigma-calibration]
//        [--noise-correlation PX] [--room-frames N] [--per-room FILE] [--against FILE] [--PARAM VALUE ...]
// (see --help)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <future>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "hough_plane_detector/sim/random_scene.h"
#include "hough_plane_detector/sim/room_statistics.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "hough_plane_detector/tools/cli_options.h"
#include "osd_learn.h"
#include "paper_experiments.h"

using namespace hough_plane_detector;

namespace
{
constexpr int kRoomFrames = 30;   // as make evaluate's procedural rooms
constexpr int kTableThreeFrames = 60;
constexpr int kFigureSevenFrames = 48;
constexpr int kFigureSevenStride = 4;
double noise_correlation_px = 0.0;  // --noise-correlation: the renderer's correlated noise (KinectNoise)
int room_frames = kRoomFrames;      // --room-frames: frames per room tour, a multiple of kRoomFrames
bool sigma_calibration = false;     // --sigma-calibration: collect and print SetResult::sigma_ratios

struct SetResult
{
  explicit SetResult(std::string set_name) : name(std::move(set_name)) {}

  std::string name;
  MethodStats stats;
  std::vector<RoomCounts> rooms;  // one per camera path, for the intervals over rooms
  std::map<std::string, int> causes;  // our misses by cause
  std::map<std::string, int> false_kinds;  // false detections by this frame's fit of them and the truth near
  std::vector<std::string> listed;  // one line per false or missed plane of a scored frame
  std::vector<double> sigma_ratios;  // each new fitting region's normal error over its normal_sigma
};

// A new surface's own fit (not snapped, fitting its blocks, no map plane's re-measurement): its
// normal's angle to the true plane its centroid lies on (within 3 cm), over its normal_sigma.
void addSigmaRatios(const PlaneDetector& detector, const std::vector<TruePlane>& truth, std::vector<double>& ratios)
{
  constexpr double kOnPlane = 0.03, kNearAngle = 0.15;
  const std::vector<FramePlane>& planes = detector.lastFramePlanes();
  const std::vector<FirstSight>& first_sights = detector.map().lastFirstSights();
  for (size_t i = 0; i < planes.size() && i < first_sights.size(); ++i)
  {
    const FramePlane& p = planes[i];
    if (p.parallel || !p.fits_its_blocks || !(p.normal_sigma > 0.0) || first_sights[i] == FirstSight::kKnownPlane)
      continue;
    double angle = kNearAngle;
    for (const TruePlane& t : truth)
      if (std::abs(t.normal.dot(p.centroid) + t.d) < kOnPlane) angle = std::min(angle, angleError(p.normal, t.normal));
    if (angle < kNearAngle) ratios.push_back(angle / p.normal_sigma);
  }
}

// A false plane: where, what, and the true plane nearest it (hidden ones too); `kind` receives
// this frame's fit of it and whether it lies near a true plane (a second plane of one surface).
std::string describeFalsePlane(const std::string& where, int frame, const PlaneDetector& detector,
                               const DetectedPlane& plane, const std::vector<TruePlane>& truth, std::string* kind)
{
  const MatchTolerance tolerance;
  double best_cost = 1e9, best_angle = 0.0, best_distance = 0.0;
  for (const TruePlane& t : truth)
  {
    const double angle = angleError(plane.normal, t.normal), distance = distanceError(plane.normal, plane.d, t.normal, t.d);
    if (angle / tolerance.angle + distance / tolerance.distance < best_cost)
    {
      best_cost = angle / tolerance.angle + distance / tolerance.distance;
      best_angle = angle;
      best_distance = distance;
    }
  }
  // This frame's fit of it, if any: snapped (parallel) or not.
  const char* fitted = "not fitted this frame";
  for (const FramePlane& f : detector.lastFramePlanes())
    if (angleError(f.normal, plane.normal) < 0.02 && distanceError(f.normal, f.d, plane.normal, plane.d) < 0.03)
      fitted = f.parallel ? "snapped or parallel search" : "own fit";
  constexpr double kNearAngle = 0.05, kNearDistance = 0.05;  // rad, m: a duplicate's reach
  char near[96];
  std::snprintf(near, sizeof(near), ", within %.2f rad and %.0f cm of a true plane", kNearAngle, 100.0 * kNearDistance);
  *kind = std::string(fitted) +
          (best_angle <= kNearAngle && best_distance <= kNearDistance ? near : ", off every true plane");
  char line[400];
  std::snprintf(line, sizeof(line),
                "%s frame %2d: id %d n (%+.3f %+.3f %+.3f) d %+.3f support %d, seen %.1f s, depths confirmed it "
                "%lld / contradicted it %lld frames; nearest true plane %.3f rad, %.3f m off; this frame: %s",
                where.c_str(), frame, plane.id, plane.normal.x(), plane.normal.y(), plane.normal.z(), plane.d,
                plane.support, plane.last_seen - plane.first_seen, static_cast<long long>(plane.confirmations),
                static_cast<long long>(plane.contradictions), best_angle, best_distance, fitted);
  return line;
}

using ParamsFor = std::function<DetectorParams(double noise)>;

// One camera path through one scene, scored at `scoring`'s frames; frame f's pixel noise is
// seeded noise_seed + f (a room's first: RandomScene::noiseSeed(0)).
void runSequence(const std::string& where, const Scene& scene, const std::vector<Eigen::Isometry3d>& poses, double noise,
                 uint32_t noise_seed, const TourScoring& scoring, const DetectorParams& params, SetResult& result)
{
  const SceneRenderer renderer(scene);
  PlaneDetector detector(params);
  KinectNoise kinect;
  kinect.coefficient = noise;
  kinect.correlation_px = noise_correlation_px;
  MethodStats room;  // this path's, merged into the set's at its end
  for (size_t f = 0; f < poses.size(); ++f)
  {
    const RenderedFrame frame = renderer.render(poses[f], kinect, noise_seed + static_cast<uint32_t>(f));
    detector.processFrame(frame.view(), frame.camera_to_world, 0.1 * f);
    if (sigma_calibration) addSigmaRatios(detector, renderer.truePlanes(), result.sigma_ratios);  // first sights: any frame
    if (!scoring.scored(static_cast<int>(f))) continue;
    const FrameMetrics metrics = evaluateFrame(renderer.truePlanes(), frame.visible_points, kMinVisiblePoints,
                                               evaluatedPlanes(detector.planes()));
    room.add(metrics);
    for (int k : metrics.false_indices)
    {
      std::string kind;
      result.listed.push_back("false: " + describeFalsePlane(where, static_cast<int>(f), detector, detector.planes()[k],
                                                             renderer.truePlanes(), &kind));
      ++result.false_kinds[kind];
    }
    for (int missed : metrics.missed)
    {
      const TruePlane& truth = renderer.truePlanes()[missed];
      const std::string cause = missCause(detector, truth);
      ++result.causes[cause];
      result.listed.push_back("missed: " + where + " frame " + std::to_string(f) + ": " + truth.name + " (" +
                              std::to_string(frame.visible_points[missed]) + " points): " + cause);
    }
  }
  result.stats.merge(room);
  result.rooms.push_back(room.roomCounts(where));
}

// noise_override > 0: each room at that C instead of its own, as make evaluate's verdict at C = 1.
SetResult runRooms(const char* name, const std::vector<uint32_t>& seeds, const ParamsFor& params_for,
                   double noise_override = 0.0)
{
  SetResult result(name);
  for (uint32_t seed : seeds)
  {
    RandomScene room = makeRandomScene(seed, room_frames);
    if (noise_override > 0.0) room.noise = noise_override;
    // The room's own noise seeds and scored frames, as make evaluate renders and scores them.
    runSequence("seed " + std::to_string(seed), room.scene, room.poses, room.noise, room.noiseSeed(0),
                roomTourScoring(room_frames / kRoomFrames), params_for(room.noise), result);
  }
  return result;
}

SetResult runTableThree(const ParamsFor& params_for)
{
  SetResult result("Table 3's tours");
  for (const NamedScene& named : tableThreeScenes())
    runSequence(std::string(named.name), named.scene, roomTour(kTableThreeFrames), 1.0, kRoomTourSeed,
                roomTourScoring(), params_for(1.0), result);
  return result;
}

SetResult runOtherTours(const ParamsFor& params_for)
{
  SetResult result("Table 3's scenes, other tours");
  for (const TourPath& tour : otherTourPaths())
    for (const NamedScene& named : tableThreeScenes())
      runSequence(std::string(named.name) + ", " + tour.name, named.scene,
                  roomTour(tour.frames, tour.centre, tour.radius), 1.0, tour.seed, roomTourScoring(),
                  params_for(1.0), result);
  return result;
}

SetResult runFigureSeven(const ParamsFor& params_for)
{
  // As make evaluate runs Fig. 7: the paper's thinning, the office at C = 4, resolution 1024.
  SetResult result("Fig. 7 office, C = 4, thinning");
  DetectorParams params = params_for(4.0);
  params.forgetting = kForgetByThinning;
  runSequence("office", makeOfficeRoom(), roomTour(kFigureSevenFrames), 4.0, kNoiseTourSeed,
              TourScoring{kWarmupFrames, kFigureSevenStride}, params, result);
  return result;
}

// Rooms of earlier runs (--per-room's file): set name -> its rooms.
using RoomsBySet = std::map<std::string, std::vector<RoomCounts>>;

bool readRooms(const std::string& path, RoomsBySet& sets, std::string* error)
{
  std::ifstream in(path);
  if (!in)
  {
    *error = "cannot read " + path;
    return false;
  }
  int line_number = 0;
  for (std::string line; std::getline(in, line);)
  {
    ++line_number;
    std::stringstream fields(line);
    std::string set;
    RoomCounts room;
    if (!std::getline(fields, set, '\t') || !std::getline(fields, room.room, '\t') ||
        !(fields >> room.detected >> room.visible >> room.false_detections >> room.frames))
    {
      *error = path + " line " + std::to_string(line_number) + ": not set<TAB>room<TAB>detected visible false frames";
      return false;
    }
    sets[set].push_back(room);
  }
  return true;
}

void writeRooms(std::ostream& out, const SetResult& r)
{
  for (const RoomCounts& room : r.rooms)
    out << r.name << '\t' << room.room << '\t' << room.detected << ' ' << room.visible << ' ' << room.false_detections
        << ' ' << room.frames << '\n';
}

// How far new surfaces' own fits lie off their truth, in their normal_sigma: the first-sight
// report trusts that sigma. Were it exact in both tilt directions, the ratio would follow a
// Rayleigh distribution: median 1.18, above 2 in 13.5 %, above 2 sqrt(2) in 1.8 %.
void printSigmaCalibration(std::vector<double> ratios)
{
  if (ratios.empty()) return;
  std::sort(ratios.begin(), ratios.end());
  const double n = static_cast<double>(ratios.size());
  auto above = [&](double x) { return 100.0 * static_cast<double>(ratios.end() - std::upper_bound(ratios.begin(), ratios.end(), x)) / n; };
  std::printf("    new fitting regions' normal error / normal_sigma (%zu fits): median %.2f, q95 %.2f, above 2: %.1f %%, "
              "above 2 sqrt(2): %.1f %% (Rayleigh: 1.18, 2.45, 13.5 %%, 1.8 %%)\n",
              ratios.size(), ratios[ratios.size() / 2], ratios[static_cast<size_t>(0.95 * (n - 1))], above(2.0),
              above(2.0 * M_SQRT2));
}

void print(const SetResult& r, bool causes, bool list, const RoomsBySet& earlier)
{
  std::printf("%-32s %5.1f %% (%d/%d)  false/frame %.3f  E_angle %.4f  E_d %.4f  frames %d\n", r.name.c_str(),
              r.stats.detectionPercent(), r.stats.detected, r.stats.visible, r.stats.falsePerFrame(), mean(r.stats.angle),
              mean(r.stats.d), r.stats.frames);
  if (r.rooms.size() > 1)
  {
    const RoomFigures spread = roomFigures(r.rooms);
    std::printf("    95 %% over its %zu rooms: found %.1f-%.1f %%, false/frame %.3f-%.3f\n", r.rooms.size(),
                spread.found_percent.low, spread.found_percent.high, spread.false_per_frame.low,
                spread.false_per_frame.high);
  }
  const auto then = earlier.find(r.name);
  if (then != earlier.end())
  {
    const RoomEffect effect = pairedRoomEffect(then->second, r.rooms);
    std::printf("    against --against's run, %d of %d rooms changed: found %+.2f %% (95 %% %+.2f..%+.2f), false/frame "
                "%+.4f (95 %% %+.4f..%+.4f)\n",
                effect.rooms_changed, effect.rooms, effect.found_percent.value, effect.found_percent.low,
                effect.found_percent.high, effect.false_per_frame.value, effect.false_per_frame.low,
                effect.false_per_frame.high);
  }
  if (sigma_calibration) printSigmaCalibration(r.sigma_ratios);
  if (list)
    for (const std::string& line : r.listed) std::printf("    %s\n", line.c_str());
  if (!causes) return;
  for (const auto& cause : r.causes) std::printf("    %4d  %s\n", cause.second, cause.first.c_str());
  if (!r.false_kinds.empty()) std::printf("    false detections, by this frame's fit of them and the truth near them:\n");
  for (const auto& kind : r.false_kinds) std::printf("    %4d  %s\n", kind.second, kind.first.c_str());
}
}  // namespace

int main(int argc, char** argv)
{
  namespace po = boost::program_options;
  std::string sets = "tuning,development,development-c1,development-b,development-b-own,development-c,table3,other,fig7",
              osd_dir, per_room_path, against_path;
  DetectorParams scratch;  // the flags' values are checked here, then applied to every detector
  po::options_description options("options"), detector_options("detector parameters (applied to every run)"), hidden;
  options.add_options()("help,h", "this help")
      ("sets", po::value(&sets)->value_name("LIST"),
       "comma-separated: tuning (seeds 901-908), development (950-965), development-c1 (the same at C = 1), "
       "development-b (300-339 at C = 1), development-b-own (the same at each room's C), development-c (600-679 at "
       "each room's C), development-c-c1 (the same at C = 1, the held-out verdict's condition; not in the default), "
       "development-d (700-899 at C = 1, as the held-out verdict; not in the default), seed-N (room N alone at C = 1), "
       "table3, other, fig7 "
       "(default: all but development-c-c1 and development-d)")
      ("osd", po::value(&osd_dir)->value_name("DIR"), "also osd-learn's real frames (annotations.json beside learn*.pcd)")
      ("causes", "our misses of each set by what became of their candidate, and its false detections by this "
                 "frame's fit of them and whether a true plane lies near")
      ("sigma-calibration", "how far new surfaces' own fits lie off their true planes, in their normal_sigma")
      ("noise-correlation", po::value(&noise_correlation_px)->value_name("PX"),
       "render spatially correlated noise, a field smoothed over PX pixels (real frames' structure; default 0: "
       "independent per pixel, as make evaluate renders)")
      ("room-frames", po::value(&room_frames)->value_name("N"),
       "tour each procedural room in N frames (a multiple of 30; default 30, as make evaluate) along the same circle, "
       "scored at the same viewpoints: a denser stream, as a camera at a higher frame rate sends")
      ("list", "every false plane of a scored frame (with the true plane nearest it) and every missed one (with its cause)")
      ("per-room", po::value(&per_room_path)->value_name("FILE"),
       "write each room's (camera path's) counts to FILE, for a later run's --against")
      ("against", po::value(&against_path)->value_name("FILE"),
       "a --per-room file of an earlier run (the detector before a change): each set's effect, paired by room, with "
       "its 95 % interval over rooms and how many rooms changed");
  addDetectorParamOptions(scratch, detector_options, hidden);
  po::options_description all;
  all.add(options).add(detector_options).add(hidden);
  po::variables_map values;
  std::string error;
  if (!parseCommandLine(argc, argv, all, po::positional_options_description(), values, &error))
  {
    std::cerr << "tuning_check: " << error << "\nusage: tuning_check [options] (see --help)\n";
    return 2;
  }
  if (values.count("help"))
  {
    std::cout << "usage: tuning_check [options]\n" << options << detector_options;
    return 0;
  }
  sigma_calibration = values.count("sigma-calibration") > 0;
  if (room_frames < kRoomFrames || room_frames % kRoomFrames != 0)
  {
    std::cerr << "tuning_check: --room-frames must be a multiple of " << kRoomFrames << ", got " << room_frames << "\n";
    return 2;
  }
  std::vector<std::pair<std::string, std::string>> overrides;
  for (const auto& value : values)
    if (detector_options.find_nothrow(value.first, false))  // the detector's parameters, not this tool's options
      overrides.emplace_back(value.first, value.second.as<std::string>());
  // Each room's sensor_noise as make evaluate sets it, then the flags given.
  const ParamsFor params_for = [&overrides](double noise) {
    DetectorParams params = paramsFor(noise, 1024);
    for (const auto& o : overrides)
    {
      std::string name = o.first;
      for (char& c : name)
        if (c == '-') c = '_';
      setDetectorParam(params, name, o.second, nullptr);  // checked when parsed
    }
    return params;
  };
  RoomsBySet earlier;
  if (!against_path.empty() && !readRooms(against_path, earlier, &error))
  {
    std::cerr << "tuning_check: --against: " << error << "\n";
    return 2;
  }
  std::ofstream per_room;
  if (!per_room_path.empty())
  {
    per_room.open(per_room_path);
    if (!per_room)
    {
      std::cerr << "tuning_check: --per-room: cannot write " << per_room_path << "\n";
      return 2;
    }
  }
  std::vector<std::function<SetResult()>> runs;
  std::stringstream list(sets);
  for (std::string set; std::getline(list, set, ',');)
  {
    if (set == "tuning")
      runs.push_back([&] { return runRooms("tuning seeds", kTuningSeeds, params_for); });
    else if (set == "development")
      runs.push_back([&] { return runRooms("development seeds", kDevelopmentSeeds, params_for); });
    else if (set == "development-c1")
      runs.push_back([&] { return runRooms("development seeds, C = 1", kDevelopmentSeeds, params_for, 1.0); });
    else if (set == "development-b")
      runs.push_back([&] { return runRooms("development B seeds, C = 1", kSecondDevelopmentSeeds, params_for, 1.0); });
    else if (set == "development-b-own")
      runs.push_back([&] { return runRooms("development B seeds, own C", kSecondDevelopmentSeeds, params_for); });
    else if (set == "development-c")
      runs.push_back([&] { return runRooms("development C seeds, own C", kThirdDevelopmentSeeds, params_for); });
    else if (set == "development-c-c1")
      runs.push_back([&] { return runRooms("development C seeds, C = 1", kThirdDevelopmentSeeds, params_for, 1.0); });
    else if (set == "development-d")
      runs.push_back([&] { return runRooms("development D seeds, C = 1", kFourthDevelopmentSeeds, params_for, 1.0); });
    else if (set.rfind("seed-", 0) == 0 && set.size() > 5 &&
             set.find_first_not_of("0123456789", 5) == std::string::npos)
    {
      // One procedural room at C = 1: a room a set's --per-room file singles out, with --list.
      const std::vector<uint32_t> one{static_cast<uint32_t>(std::stoul(set.substr(5)))};
      runs.push_back([&, one] { return runRooms("one room, C = 1", one, params_for, 1.0); });
    }
    else if (set == "table3")
      runs.push_back([&] { return runTableThree(params_for); });
    else if (set == "other")
      runs.push_back([&] { return runOtherTours(params_for); });
    else if (set == "fig7")
      runs.push_back([&] { return runFigureSeven(params_for); });
    else
    {
      std::cerr << "tuning_check: unknown set '" << set << "' (tuning, development, development-c1, development-b, development-b-own, development-c, development-c-c1, development-d, seed-N, table3, other, fig7)\n";
      return 2;
    }
  }
  // The sets are independent: all at once, one thread each (a detector and its renderer per run).
  std::vector<std::future<SetResult>> results;
  for (const auto& run : runs) results.push_back(std::async(std::launch::async, run));
  const bool causes = values.count("causes") > 0;
  const bool list_planes = values.count("list") > 0;
  for (auto& future : results)
  {
    const SetResult result = future.get();
    print(result, causes, list_planes, earlier);
    if (per_room.is_open()) writeRooms(per_room, result);
  }
  if (osd_dir.empty()) return 0;
  OsdResults osd;
  DetectorParams osd_params = params_for(0.0);
  assumeCameraFrame(values, osd_params);
  if (!evaluateOsdLearn(osd_dir, osd_params, false, false, "", osd, &error))
  {
    std::cerr << "tuning_check: " << error << "\n";
    return 1;
  }
  const OsdMethodResult& one = osd.methods.front();
  std::printf("%-32s %5.1f %% (%d/%d)  duplicates/frame %.2f  on cans %d  E_angle %.4f  E_d %.4f  frames %d\n",
              "osd-learn, one frame", one.foundPercent(), one.found, one.entries,
              static_cast<double>(one.duplicates) / one.frames, one.curved_planes, mean(one.angle_errors),
              mean(one.d_errors), one.frames);
  if (causes)
    for (const auto& reason : osd.misses_by_reason) std::printf("    %4d  %s\n", reason.second, reason.first.c_str());
  return 0;
}
