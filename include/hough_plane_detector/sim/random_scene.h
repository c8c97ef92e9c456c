// Procedural rooms for a held-out evaluation: every seed gives a room of its own size and yaw
// with stairs, a ramp, a sloped ceiling, tables, shelving, stacked boxes, an open door and
// curved clutter (each present or not by chance), a camera tour inside it and a noise level.
// Thresholds are chosen on tuning seeds; figures are reported on held-out seeds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "hough_plane_detector/sim/scene_renderer.h"

namespace hough_plane_detector
{

struct RandomScene
{
  uint32_t seed = 0;
  Scene scene;
  std::vector<Eigen::Isometry3d> poses;  // the camera's tour
  double noise = 1.0;                    // C of eq. 11 for this scene, in [0.5, 2]
  std::string description;               // what the room holds, for reports
  // The pixel-noise seed of the tour's frame `frame`, as make evaluate, tuning_check and the
  // tests render it: the same room, frame and C give the same depths everywhere.
  uint32_t noiseSeed(int frame) const { return seed * 1000 + static_cast<uint32_t>(frame); }
};

// The room of a seed; the same seed always gives the same room, tour and noise.
RandomScene makeRandomScene(uint32_t seed, int frames);

// Seeds written down before any threshold was chosen on random scenes: figures are reported on
// these (kSecondHeldOutSeeds, 121-160, and kThirdHeldOutSeeds, 501-540, were added later,
// each before any run on it). Tuning (looking at results, changing the detector) uses
// kTuningSeeds, kDevelopmentSeeds, a wider set whose misses were looked at one by one, and
// kSecondDevelopmentSeeds (300-339, at C = 1) and kThirdDevelopmentSeeds (600-679, at each
// room's C: false planes are rare events, and 40 rooms left their rate uncertain) and
// kFourthDevelopmentSeeds (700-899, at C = 1); seeds 400-459 were looked at while the
// close-surface peaks were developed. None of those is reported as held out.
extern const std::vector<uint32_t> kHeldOutSeeds;
extern const std::vector<uint32_t> kSecondHeldOutSeeds;
extern const std::vector<uint32_t> kThirdHeldOutSeeds;
extern const std::vector<uint32_t> kTuningSeeds;
extern const std::vector<uint32_t> kDevelopmentSeeds;
extern const std::vector<uint32_t> kSecondDevelopmentSeeds;
extern const std::vector<uint32_t> kThirdDevelopmentSeeds;
extern const std::vector<uint32_t> kFourthDevelopmentSeeds;

}  // namespace hough_plane_detector
