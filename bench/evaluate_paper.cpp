// The paper's section 4 regenerated from this code (bench/paper_experiments.h runs the
// experiments): this program writes what they return as OUT_DIR/RESULTS.md, with a verdict per
// target or comparison, and the gnuplot data files OUT_DIR/results/*.dat, which
// scripts/evaluate.sh plots into OUT_DIR/results/*.png.
// Usage: evaluate_paper OUT_DIR [--quick] [--osd OSD_LEARN_DIR] [FRAME.pcd ...]
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "hough_plane_detector/tools/cli_options.h"
#include "osd_learn.h"
#include "paper_experiments.h"
#include "pcl_comparators.h"
#include "stopwatch.h"

using namespace hough_plane_detector;

namespace
{
std::string fmt(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string fmt(const char* format, ...)
{
  // Sized by a first pass: report paragraphs outgrow any fixed buffer.
  va_list args, again;
  va_start(args, format);
  va_copy(again, args);
  const int length = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(length > 0 ? static_cast<size_t>(length) : 0, '\0');
  if (length > 0) std::vsnprintf(&text[0], text.size() + 1, format, again);
  va_end(again);
  return text;
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

std::string causeList(const std::map<std::string, int>& causes)
{
  std::string list;
  for (const auto& [cause, frames] : causes) list += fmt("%s%s: %d", list.empty() ? "" : "; ", cause.c_str(), frames);
  return list;
}

// The one writer of RESULTS.md and the .dat files.
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
  std::string picturesDir() const { return out_dir + "/results"; }
};

// Figures 6 and 7.
void writeNoiseExperiment(const NoiseExperiment& e, Report& report)
{
  auto memory_file = report.data("fig6_memory.dat");
  auto accuracy_file = report.data("fig7_accuracy.dat");
  memory_file << "# frame, Hough-space MB at resolution 1024 for C = 0, 0.3, 1.0, 4.0, then the dense array's MB\n";
  accuracy_file << "# C, then E_angle mean, E_angle std, E_d mean, E_d std for: hough512 hough1024 hough2048 ransac "
                   "organized\n";
  std::string table = "| C | method | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  std::string memory_table = "| C | Hough space after the run (MB) | peak (MB) | chunks | share of the dense array |\n"
                             "|---|---|---|---|---|\n";
  for (const NoiseLevelResult& level : e.levels)
  {
    const double noise = level.noise;
    memory_table += fmt("| %.1f | %.2f | %.2f | %zu | %.3f %% |\n", noise, level.final_mb, level.peak_mb,
                        level.final_chunks, 100.0 * level.final_dense_share);
    accuracy_file << noise;
    for (const MethodStats* s : {&level.ours[0], &level.ours[1], &level.ours[2], &level.ransac, &level.organized})
    {
      // No matched plane: no error to plot (not an error of zero).
      const double nan = std::numeric_limits<double>::quiet_NaN();
      accuracy_file << ' ' << (s->angle.empty() ? nan : mean(s->angle)) << ' ' << standardDeviation(s->angle) << ' '
                    << (s->d.empty() ? nan : mean(s->d)) << ' ' << standardDeviation(s->d);
    }
    accuracy_file << '\n';
    for (int r = 0; r < kResolutionCount; ++r)
      table += fmt("| %.1f ", noise) + accuracyRow(fmt("Hough %d", kResolutions[r]), level.ours[r]);
    table += fmt("| %.1f ", noise) +
             accuracyRow(fmt("PCL RANSAC (%.2f m, %d it)", ransacThreshold(noise), e.ransac_iterations), level.ransac);
    table += fmt("| %.1f ", noise) + accuracyRow("PCL OMPS", level.organized);
    const MethodStats& best = level.ours[1];
    report.verdict(mean(best.angle) <= mean(level.ransac.angle),
                   fmt("Fig. 7, C = %.1f: Hough 1024 E_angle %.4f rad vs RANSAC %.4f", noise, mean(best.angle),
                       mean(level.ransac.angle)));
    report.verdict(mean(best.d) <= mean(level.ransac.d), fmt("Fig. 7, C = %.1f: Hough 1024 E_d %.4f m vs RANSAC %.4f",
                                                             noise, mean(best.d), mean(level.ransac.d)));
    report.verdict(best.detectionPercent() >= level.ransac.detectionPercent(),
                   fmt("Fig. 7, C = %.1f: Hough 1024 detects %.1f %% vs RANSAC %.1f %%", noise,
                       best.detectionPercent(), level.ransac.detectionPercent()));
  }
  for (int f = 0; f < e.frames; ++f)
  {
    memory_file << f;
    for (double mb : e.memory_mb[f]) memory_file << ' ' << mb;
    memory_file << ' ' << e.dense_mb << '\n';
  }
  report.md << "## Fig. 6: Hough-space memory against noise\n\n"
            << fmt("The office tour (%d frames, one turn), resolution 1024, after every frame. The dense 1024-grid "
                   "array would take %.0f MB. PCL's methods keep no accumulator, so they have no counterpart here.\n\n",
                   e.frames, e.dense_mb)
            << memory_table << "\n![Fig. 6](results/fig6_memory.png)\n\n";
  report.md << "## Fig. 7: accuracy against noise and resolution\n\n"
            << fmt("The same office tour at each noise level C. Our detector runs on every frame and its map is "
                   "scored on every %d-th frame from frame %d; PCL RANSAC (iterative SACSegmentation, least-squares "
                   "refinement, %d iterations per plane, inlier threshold by noise as in the paper) and PCL OMPS run "
                   "on exactly those frames. Planes with at least %d visible points count; E_angle and E_d are over "
                   "matched planes, mean +- standard deviation.\n\n",
                   e.stride, kWarmupFrames, e.ransac_iterations, kMinVisiblePoints)
            << table << "\n![Fig. 7](results/fig7_accuracy.png)\n\n";
}

// Figure 8.
void writeWallApproach(const WallExperiment& e, Report& report)
{
  auto file = report.data("fig8_wall.dat");
  file << "# frame, true distance to the wall (m), detected distance: hough1024 ransac organized (nan = not found)\n";
  std::vector<double> errors[3];
  int found[3] = {0, 0, 0};
  for (int f = 0; f < e.frames; ++f)
  {
    file << f << ' ' << e.truth[f];
    for (int m = 0; m < 3; ++m)
    {
      file << ' ' << e.found[f][m];
      if (std::isnan(e.found[f][m])) continue;
      ++found[m];
      errors[m].push_back(e.found[f][m] - e.truth[f]);
    }
    file << '\n';
  }
  const std::string names[3] = {"Hough 1024 (map)",
                                fmt("PCL RANSAC (%.2f m, %d it)", ransacThreshold(e.noise), e.ransac_iterations),
                                "PCL OMPS"};
  report.md << "## Fig. 8: stability while approaching a wall\n\n"
            << fmt("A camera drives at the office's east wall from 5.0 m to 0.8 m in %d frames (C = %.1f). Per frame, "
                   "each method's plane nearest the wall (within 0.1 rad and 0.5 m) gives the distance to the wall; "
                   "error = detected - true.\n\n",
                   e.frames, e.noise)
            << "| method | frames with the wall | mean error (m) | std of the error (m) | worst error (m) |\n"
               "|---|---|---|---|---|\n";
  for (int m = 0; m < 3; ++m)
  {
    double worst = 0;
    for (double error : errors[m]) worst = std::max(worst, std::abs(error));
    report.md << fmt("| %s | %d / %d | %+.4f | %.4f | %.4f |\n", names[m].c_str(), found[m], e.frames, mean(errors[m]),
                     standardDeviation(errors[m]), worst);
  }
  report.md << "\n![Fig. 8](results/fig8_wall.png)\n\n";
  report.verdict(standardDeviation(errors[0]) <= standardDeviation(errors[1]) / 3.0,
                 fmt("Fig. 8: std of the wall's error %.4f m is at most a third of RANSAC's %.4f m",
                     standardDeviation(errors[0]), standardDeviation(errors[1])));
  report.verdict(found[0] >= found[1], fmt("Fig. 8: wall found in %d frames vs RANSAC's %d", found[0], found[1]));
}

// Table 3's losses, per plane: every plane some frame showed and our map missed, with the
// frames each method missed it and why ours did.
std::string missTable(const std::string& scene, const TourResult& tour)
{
  std::string rows;
  for (const auto& [plane, causes] : tour.tally.ours_causes)
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
    rows += fmt("| %s | %s | %d | %d (%s) | %d | %d |\n", scene.c_str(), tour.truth[plane].name.c_str(),
                tour.tally.visible_frames.at(plane), ours, why.c_str(), missedBy(tour.ransac), missedBy(tour.organized));
  }
  return rows;
}

// 4.6.4: timing from the Table 3 runs (every frame for ours, the scored frames for PCL's).
void writeTiming(const MethodStats& all_ours, const MethodStats& all_ransac, const MethodStats& all_organized,
                 Report& report)
{
  auto file = report.data("timing.dat");
  file << "# method, median ms, p10, p90, mean, std\n";
  report.md << "## Time per frame (4.6.4)\n\n"
            << "From the Table 3 runs above: one method at a time, 640 x 480 frames, on this machine; ours measures each frame on two threads (measurement_threads), the rest of ours and PCL's methods run on one.\n\n"
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

// Table 3 and 4.6.4.
void writeRoomTours(const RoomExperiment& e, Report& report)
{
  const std::string ransac_name = fmt("PCL RANSAC (%.2f m, %d it)", e.ransac_threshold, e.ransac_iterations);
  MethodStats all_ours, all_ransac, all_organized;
  std::string table = "| scene | method | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  std::string misses;
  for (const SceneTour& scene : e.scenes)
  {
    const TourResult& tour = scene.tour;
    misses += missTable(scene.scene, tour);
    table += fmt("| %s ", scene.scene.c_str()) + accuracyRow("Hough 1024 (map)", tour.ours);
    table += fmt("| %s ", scene.scene.c_str()) + accuracyRow(ransac_name, tour.ransac);
    table += fmt("| %s ", scene.scene.c_str()) + accuracyRow("PCL OMPS", tour.organized);
    all_ours.merge(tour.ours);
    all_ransac.merge(tour.ransac);
    all_organized.merge(tour.organized);
  }
  table += "| **all scenes** " + accuracyRow("**Hough 1024 (map)**", all_ours);
  table += "| **all scenes** " + accuracyRow(ransac_name, all_ransac);
  table += "| **all scenes** " + accuracyRow("PCL OMPS", all_organized);
  report.md << "## Table 3: Kinect-like room sequences (C = 1.0)\n\n"
            << fmt("Each scene is toured in %d frames (a camera 1 m high circling the room centre, 20 deg down) with "
                   "eq. 11 noise at C = %.1f and 1/8-pixel disparity quantization. Our map is scored on every %d-th "
                   "frame from frame %d, the PCL methods run on exactly those frames. Detected = true planes with at "
                   "least %d visible points matched by a detection (within 0.08 rad and 0.07 m, one to one); false = "
                   "detections matching no plane of the scene.\n\n",
                   e.frames, e.noise, e.stride, kWarmupFrames, kMinVisiblePoints)
            << table << '\n';
  const std::string cause_list = causeList(e.causes);
  report.md << "### Where our map misses planes (Table 3 frames)\n\n"
            << "Every plane a scored frame showed with enough points and our map did not match, with the frames "
               "each method missed it. Why ours did, per frame: the fate of the local Hough peak or the parallel "
               "search's cluster that matches the plane (`PlaneDetector::lastCandidates()`); when none matches, "
               "that of the nearest candidate within three tolerances (mostly a fit of the plane with a surface "
               "beside it); \"no Hough peak\" when neither a window vote above local_threshold nor a cluster of "
               "free blocks along a known normal came near it, \"seen, not yet in the map: <why>\" when the frame accepted it but the global space has "
               "not reached global_threshold, with how the frame's plane on it voted (`PlaneMap::lastFirstSights()`: "
               "what kept it from being reported at first sight), \"seen, one map plane with another surface\" when a map plane "
               "within the tolerance went to another true plane (one plane for two near surfaces).\n\n"
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

  writeTiming(all_ours, all_ransac, all_organized, report);
}

// Table 3's scenes along other paths: its thresholds were chosen while looking at Table 3's
// tours, so these show how much of its result carries over.
void writeOtherTours(const OtherToursExperiment& e, Report& report)
{
  std::string table = "| tour (all three scenes) | method | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  MethodStats all_ours, all_ransac, all_organized;
  for (const OtherTour& tour : e.tours)
  {
    table += fmt("| %s ", tour.name.c_str()) + accuracyRow("Hough 1024 (map)", tour.ours);
    if (e.with_pcl)
    {
      table += fmt("| %s ", tour.name.c_str()) + accuracyRow("PCL RANSAC", tour.ransac);
      table += fmt("| %s ", tour.name.c_str()) + accuracyRow("PCL OMPS", tour.organized);
    }
    all_ours.merge(tour.ours);
    all_ransac.merge(tour.ransac);
    all_organized.merge(tour.organized);
  }
  table += "| **all these tours** " + accuracyRow("**Hough 1024 (map)**", all_ours);
  if (e.with_pcl)
  {
    table += "| **all these tours** " + accuracyRow("PCL RANSAC", all_ransac);
    table += "| **all these tours** " + accuracyRow("PCL OMPS", all_organized);
  }
  const std::string cause_list = causeList(e.causes);
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

// Table 3's tours, ours only: the default beside the paper's per-frame stage and thinning.
void writeStageAndForgettingTours(const std::vector<StageRow>& rows, Report& report)
{
  MethodStats windows, regions, thinning;
  std::string table = "| scene | per-frame stage | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  for (const StageRow& row : rows)
  {
    table += fmt("| %s ", row.scene.c_str()) + accuracyRow("block regions (default)", row.regions);
    table += fmt("| %s ", row.scene.c_str()) + accuracyRow("windows (region_growing 0)", row.windows);
    table += fmt("| %s ", row.scene.c_str()) + accuracyRow("forgetting by thinning (forgetting 0, the paper)", row.thinning);
    thinning.merge(row.thinning);
    windows.merge(row.windows);
    regions.merge(row.regions);
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

// Procedural rooms: the held-out seeds decide, the tuning seeds are shown beside them.
void writeRandomScenes(const RandomSceneExperiment& e, Report& report)
{
  std::string table = "| seeds | detector | E_angle (rad) | E_d (m) | detected | false / frame | frames |\n"
                      "|---|---|---|---|---|---|---|\n";
  for (size_t v = 0; v < e.variants.size(); ++v)
    table += fmt("| %zu held-out ", e.held_out_seeds) + accuracyRow(e.variants[v], e.held_out[v]);
  table += fmt("| %zu held-out, at C = 1 ", e.held_out_seeds) + accuracyRow(e.variants.front(), e.held_out_at_c1);
  // The verdict pools the held-out lists: the later ones make the false-plane rate firmer.
  MethodStats pooled = e.held_out.front(), pooled_at_c1 = e.held_out_at_c1;
  pooled.merge(e.second_held_out);
  pooled_at_c1.merge(e.second_held_out_at_c1);
  pooled.merge(e.third_held_out);
  pooled_at_c1.merge(e.third_held_out_at_c1);
  const size_t all_held_out = e.held_out_seeds + e.second_held_out_seeds + e.third_held_out_seeds;
  table += fmt("| %zu second held-out ", e.second_held_out_seeds) + accuracyRow(e.variants.front(), e.second_held_out);
  table += fmt("| %zu second held-out, at C = 1 ", e.second_held_out_seeds) +
           accuracyRow(e.variants.front(), e.second_held_out_at_c1);
  table += fmt("| %zu third held-out ", e.third_held_out_seeds) + accuracyRow(e.variants.front(), e.third_held_out);
  table += fmt("| %zu third held-out, at C = 1 ", e.third_held_out_seeds) +
           accuracyRow(e.variants.front(), e.third_held_out_at_c1);
  table += fmt("| **all %zu held-out** ", all_held_out) + accuracyRow(e.variants.front(), pooled);
  table += fmt("| **all %zu held-out, at C = 1** ", all_held_out) + accuracyRow(e.variants.front(), pooled_at_c1);
  table += fmt("| all %zu held-out, at C = 1, %d-frame tours ", all_held_out, kDenserTourFactor * e.frames) +
           accuracyRow(e.variants.front(), e.held_out_at_c1_denser);
  table += fmt("| all %zu held-out, at C = 1, noise correlated over %.0f px ", all_held_out, kCorrelatedNoisePx) +
           accuracyRow(e.variants.front(), e.held_out_at_c1_correlated);
  for (size_t v = 0; v < e.variants.size(); ++v)
    table += fmt("| %zu tuning ", e.tuning_seeds) + accuracyRow(e.variants[v], e.tuning[v]);
  std::string rows;
  for (const HeldOutRoom& room : e.rooms)
    rows += fmt("| %u | %s | %.1f %% | %.2f | %.1f %% | %.2f |\n", room.seed, room.room.c_str(),
                room.defaults.detectionPercent(), room.defaults.falsePerFrame(), room.windows.detectionPercent(),
                room.windows.falsePerFrame());
  report.md << "## Procedural rooms: held-out seeds\n\n"
            << fmt("Rooms from `makeRandomScene` (src/sim/random_scene.cpp): random size (4-8 x 3.5-7 x 2.4-3.2 m) "
                   "and yaw; by chance stairs (rise 12-20 cm, run 25-35 cm), a ramp (5-20 deg), a ceiling sloping "
                   "20-45 deg, shelving with boards 30-40 cm apart, a door open 30-80 deg; always 1-2 tables, 2-5 boxes "
                   "at random yaw (some stacked), cylinders and balls; a camera circling at 0.8-1.6 m, 10-35 deg down; "
                   "eq. 11 noise with C drawn from 0.5-2 (the detector's sensor_noise = max(1, C)). %d frames a room, "
                   "scored every 3rd from frame %d as Table 3. The held-out seeds (101-120) were written down before "
                   "any threshold was chosen on these rooms and are reported only; tuning looks at seeds 901-908, "
                   "950-965, 300-339, 600-679 and 700-899 only. The rows without the parallel search, without the snap and with snaps judged by "
                   "the noise model alone (world_z_up 0: no F test of snaps off the vertical) show what each of those "
                   "rules adds. The row at C = 1 renders the same held-out rooms and paths at C = 1, the condition the "
                   "targets are stated at; the rows above it keep each room's own C. A second held-out list "
                   "(seeds 121-160, the defaults only) was written down later, before any run on it, because 20 "
                   "rooms left the false-plane rate uncertain by about half its value. A third (seeds 501-540, the "
                   "defaults only) was written down before any run on it, after seeds 101-160 had been looked at "
                   "while a rule was developed (the close-surface peaks). The verdicts pool all three "
                   "lists. The row of %d-frame tours (reported, no verdict) renders the same rooms at C = 1 along "
                   "the same circles in twice the frames, scored at the same viewpoints: the stream of a faster camera, "
                   "in which a view repeats before the next differs. The row of correlated noise (reported, no "
                   "verdict) renders them at C = 1 with the noise a field smoothed over %.0f pixels, a fifth of "
                   "eq. 11's variance, most of it shared by neighbouring pixels, as real structured-light frames "
                   "have it (`evaluate_osd --noise`); the thresholds were chosen on noise independent per pixel. "
                   "Targets on the held-out seeds: "
                   ">= 95 %% detected, <= 0.05 false planes per frame, E_angle <= 0.01 rad, E_d <= 1 cm.\n\n",
                   e.frames, kWarmupFrames, kDenserTourFactor * e.frames, kCorrelatedNoisePx)
            << table << "\n| held-out seed | room | defaults detected | false / frame | windows detected | "
                        "false / frame |\n|---|---|---|---|---|---|\n"
            << rows << '\n';
  // The rooms are a sample of rooms: the interval says how far another sample could move the figures.
  auto verdict = [&](const MethodStats& h, const std::vector<RoomCounts>& rooms, const char* which) {
    const RoomFigures spread = roomFigures(rooms);
    report.verdict(h.detectionPercent() >= 95.0 && h.falsePerFrame() <= 0.05 && mean(h.angle) <= 0.01 && mean(h.d) <= 0.01,
                   fmt("held-out procedural rooms (defaults, %s): %.1f %% detected >= 95 %%, %.3f false planes per "
                       "frame <= 0.05, E_angle %.4f rad, E_d %.4f m (95 %% over the %zu rooms: %.1f-%.1f %% detected, "
                       "%.3f-%.3f false planes per frame)",
                       which, h.detectionPercent(), h.falsePerFrame(), mean(h.angle), mean(h.d), rooms.size(),
                       spread.found_percent.low, spread.found_percent.high, spread.false_per_frame.low,
                       spread.false_per_frame.high));
  };
  verdict(pooled, e.held_out_rooms, fmt("all %zu seeds, each room's C, 0.5-2", all_held_out).c_str());
  verdict(pooled_at_c1, e.held_out_rooms_at_c1, fmt("all %zu seeds, C = 1", all_held_out).c_str());
}

// ../shared/data/kinect-real: a still camera, no ground truth; time and planes found.
void writeRealFrames(const RealFramesExperiment& e, Report& report)
{
  std::string pictures, found;
  for (const RealFrame& frame : e.frames)
  {
    if (!frame.picture.empty()) pictures += "![" + frame.picture + "](results/" + frame.picture + ") ";
    found += fmt("- %s: %zu planes:", frame.file.c_str(), frame.planes.size());
    for (const DetectedPlane& p : frame.planes)
      found += fmt(" n (%.2f, %.2f, %.2f) d %.3f m, %d points;", p.normal.x(), p.normal.y(), p.normal.z(), p.d, p.support);
    found += "\n";
  }
  report.md << "## Real Kinect frames\n\n"
            << fmt("%zu organized frames from ../shared/data/kinect-real (PCL's test data; a still camera, no ground "
                   "truth, so no accuracy: a floor, a wall and boxes). Each frame alone with the defaults, camera "
                   "frame = world frame. RANSAC as the paper on real data (0.05 m, 500 iterations).\n\n",
                   e.frames.size())
            << "| method | median ms per frame | planes in the last frame |\n|---|---|---|\n"
            << fmt("| Hough 1024 (defaults) | %.2f | see below |\n", median(e.ours_ms))
            << fmt("| PCL RANSAC (0.05 m, 500 it) | %.2f | %zu |\n", median(e.ransac_ms), e.ransac_planes)
            << fmt("| PCL OMPS | %.2f | %zu |\n\n", median(e.organized_ms), e.organized_planes) << found << '\n'
            << "Segmented (plane colours; grey: on no plane; black: no return):\n\n"
            << pictures << "\n\n";
}

// ../shared/data/osd-learn: real frames with annotated planes, with the defaults.
void writeOsdLearn(const OsdResults& results, Report& report)
{
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
}
}  // namespace

int main(int argc, char** argv)
{
  namespace po = boost::program_options;
  Report report;
  std::vector<std::string> pcds;
  std::string osd_dir;
  po::options_description options("options"), hidden;
  options.add_options()("help,h", "this help")("quick", po::bool_switch(&report.quick), "short sequences, for routine checks")
      ("osd", po::value(&osd_dir)->value_name("OSD_LEARN_DIR"), "add the annotated real frames of osd-learn");
  hidden.add_options()("out-dir", po::value(&report.out_dir))("pcd", po::value(&pcds));
  po::positional_options_description positional;
  positional.add("out-dir", 1).add("pcd", -1);
  po::options_description all;
  all.add(options).add(hidden);
  po::variables_map values;
  std::string error;
  const bool parsed = parseCommandLine(argc, argv, all, positional, values, &error);
  if (!parsed || values.count("help") || report.out_dir.empty())
  {
    if (!parsed) std::fprintf(stderr, "evaluate_paper: %s\n", error.c_str());
    std::cerr << "usage: evaluate_paper OUT_DIR [options] [FRAME.pcd ...]\n" << options;
    return values.count("help") && parsed ? 0 : 2;
  }
  const auto start = Clock::now();
  std::fprintf(stderr, "Fig. 6 and 7: noise levels\n");
  writeNoiseExperiment(runNoiseExperiment(report.quick), report);
  std::fprintf(stderr, "Fig. 8: wall approach\n");
  writeWallApproach(runWallApproach(report.quick), report);
  std::fprintf(stderr, "Table 3 and timing: room tours\n");
  writeRoomTours(runRoomTours(report.quick), report);
  std::fprintf(stderr, "Table 3's scenes along other paths\n");
  writeOtherTours(runOtherTours(report.quick), report);
  if (!pcds.empty())
  {
    RealFramesExperiment real;
    std::string error;
    if (!runRealFrames(pcds, report.picturesDir(), real, &error))
    {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 1;
    }
    writeRealFrames(real, report);
  }
  std::fprintf(stderr, "Procedural rooms: held-out seeds\n");
  writeRandomScenes(runRandomScenes(report.quick), report);
  std::fprintf(stderr, "Table 3's tours with the windows' fit\n");
  writeStageAndForgettingTours(runStageAndForgettingTours(report.quick), report);
  if (!osd_dir.empty())
  {
    std::fprintf(stderr, "osd-learn: real frames with annotated planes\n");
    OsdResults results;
    std::string error;
    if (!evaluateOsdLearn(osd_dir, cameraFrameDefaults(), true, false, report.picturesDir(), results, &error))
    {
      std::fprintf(stderr, "osd-learn: %s\n", error.c_str());
      return 1;
    }
    writeOsdLearn(results, report);
  }

  std::ofstream out(report.out_dir + "/RESULTS.md");
  out << "# Results: the paper's experiments, regenerated\n\n"
      << "Written by `make evaluate" << (report.quick ? " QUICK=1" : "")
      << "` (bench/evaluate_paper.cpp, plots by scripts/evaluate.sh with gnuplot); "
      << (report.quick ? "QUICK=1: short sequences and few comparator frames, for routine checks only. "
                       : "the full run. ")
      << fmt("Every number below comes from one run on this machine (%.0f s). Our detector runs with its defaults "
             "(resolution as stated, `sensor_noise` = max(1, C)), except that Fig. 6-8 use the paper's thinning "
             "(`forgetting 0`); the PCL methods get the same frames as PCL point clouds.\n\n",
             msSince(start) / 1000.0)
      << "## Targets and comparisons\n\n";
  for (const auto& line : report.verdicts) out << line << '\n';
  out << '\n' << report.md.str();
  std::fprintf(stderr, "wrote %s/RESULTS.md in %.0f s\n", report.out_dir.c_str(), msSince(start) / 1000.0);
  return 0;
}
