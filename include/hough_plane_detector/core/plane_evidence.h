// Forgetting by evidence (forgetting = 1): each frame, a map plane the camera could have seen
// is checked against the frame's depths where its known extent projects. A depth on the plane
// confirms it; a depth clearly behind it (the ray passed through where the plane should be)
// contradicts it; no return, or something in front of it, is no evidence. The plane's
// log-odds follow the evidence with clamping, as octomap's cells do; planes out of view keep
// theirs.
#pragma once

#include <cstdint>

#include <Eigen/Geometry>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/plane_extent.h"
#include "hough_plane_detector/core/sensor_model.h"

namespace hough_plane_detector
{

struct PlaneEvidence
{
  int confirmed = 0;     // checked extent cells whose pixel's depth lies on the plane
  int contradicted = 0;  // checked extent cells whose pixel's depth lies clearly behind it
};

// Checks the live cells of `extent` on a 10 cm lattice (plane normal . p + d = 0, world frame) against the
// organized cloud seen from camera_to_world with the given projection and noise.
PlaneEvidence checkPlaneEvidence(const PlaneExtent& extent, const Eigen::Vector3d& normal, double d,
                                 const CloudView& cloud, const Eigen::Isometry3d& camera_to_world,
                                 const PinholeIntrinsics& intrinsics, const DepthNoiseModel& noise, int64_t frame,
                                 float fade_per_frame);

// Log-odds of a map plane, clamped as octomap's: a frame that mostly confirms a plane adds
// kHit, one that mostly contradicts it adds kMiss (negative); below kRemoveBelow it is gone.
struct PlaneBelief
{
  static constexpr double kHit = 0.4;
  static constexpr double kMiss = -0.4;
  static constexpr double kMax = 3.5;
  static constexpr double kMin = -2.0;
  static constexpr double kStart = 1.0;
  static constexpr double kRemoveBelow = 0.0;
  // Fewer checked cells than this (on a 10 cm lattice: 0.05 m^2) in view say nothing either way.
  static constexpr int kMinCells = 5;
  // Frames that must confirm a plane before it keeps its state out of view (0.2 s at 30 Hz):
  // until then it fades as in the paper, so a plane one view suggested (a pillar's tangent)
  // does not stay for good once the camera turns away.
  static constexpr int64_t kEstablishedAfter = 6;
  // Votes a tentative plane loses per frame that does not measure it again (a frame's vote adds 1).
  static constexpr double kTentativeFade = 0.5;

  double log_odds = kStart;
  int64_t confirmations = 0;    // frames that confirmed it
  int64_t contradictions = 0;   // frames that contradicted it
  // Frames that measured it as one surface (PlaneMap::vouchesForOneSurface). Depths within
  // 3 sigma + 2 cm confirm a plane fitted through two surfaces too (a box's side and the face of
  // the box stacked on it), in every frame that sees them from about the same view; only a
  // measurement whose blocks lie on the plane within their noise tells one surface from such a mix.
  int64_t one_surface_measurements = 0;

  // Applies one frame's evidence; true when it changed the belief.
  bool update(const PlaneEvidence& evidence);
  bool gone() const { return log_odds < kRemoveBelow; }
  bool established() const { return confirmations >= kEstablishedAfter && one_surface_measurements > 0; }
  // Seen in one frame only (no later frame has confirmed it), or never measured as one surface.
  bool tentative() const { return (confirmations == 0 || one_surface_measurements == 0) && !gone(); }
};

}  // namespace hough_plane_detector
