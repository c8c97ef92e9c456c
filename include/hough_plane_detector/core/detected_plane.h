// A plane of the persistent map, as the detector reports it.
#pragma once

#include <cstdint>

#include <Eigen/Core>

namespace hough_plane_detector
{

struct DetectedPlane
{
  int id = -1;                                        // stable across frames
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, world frame
  double d = 0.0;                                     // normal.p + d = 0 in the world frame
  double strength = 0.0;                              // global Hough value (about frames seen)
  int support = 0;                                    // points of the current frame on the plane
  double first_seen = 0.0;                            // stamp of the first frame it was reported
  double last_seen = 0.0;                             // stamp of the last frame with min_support points
  Eigen::Vector3d hough = Eigen::Vector3d::Zero();    // canonical (alpha, beta, d) of its peak
  int64_t confirmations = 0;   // forgetting by evidence: frames whose depths confirmed it
  int64_t contradictions = 0;  // ... and frames whose rays passed through where it should be
};

}  // namespace hough_plane_detector
