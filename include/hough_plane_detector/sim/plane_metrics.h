// The paper's error metrics (4.4, eq. 12-14) and false detections.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "hough_plane_detector/core/detected_plane.h"
#include "hough_plane_detector/sim/scene_renderer.h"

namespace hough_plane_detector
{

struct EvaluatedPlane
{
  Eigen::Vector3d normal;
  double d;
};

// A detector's map planes as the metrics score them (world frame).
std::vector<EvaluatedPlane> evaluatedPlanes(const std::vector<DetectedPlane>& planes);

struct MatchTolerance
{
  double angle = 0.08;    // rad: a detection farther off than this matches no true plane
  double distance = 0.07; // m
};

struct FrameMetrics
{
  int visible = 0;               // |P|: true planes with enough visible points
  int detected = 0;              // of those, matched by a detection
  int false_detections = 0;      // detections that match no true plane of the scene
  std::vector<int> false_indices;  // ... their indices in the detections
  std::vector<double> angle_errors;  // E_angle per matched visible plane (eq. 12)
  std::vector<double> d_errors;      // E_d per matched visible plane (eq. 13)
  std::vector<int> missed;           // indices of the visible true planes no detection matched
  double missRate() const { return visible > 0 ? 1.0 - static_cast<double>(detected) / visible : 0.0; }  // eq. 14
};

// E_angle of two planes, independent of the normals' signs.
double angleError(const Eigen::Vector3d& normal, const Eigen::Vector3d& true_normal);
// E_d after aligning the sign of the normal with the true one.
double distanceError(const Eigen::Vector3d& normal, double d, const Eigen::Vector3d& true_normal, double true_d);

// The true plane closest to (normal, d) in units of the match tolerance (angle / tolerance.angle
// + distance / tolerance.distance), if that cost is at most max_cost; else nullptr.
const TruePlane* nearestTruePlane(const Eigen::Vector3d& normal, double d, const std::vector<TruePlane>& truth,
                                  double max_cost = 2.0, const MatchTolerance& tolerance = MatchTolerance());

// One-to-one matching (closest pairs first, visible planes before hidden ones) of detections to all
// true planes of the scene; planes with at least min_visible_points count as visible.
FrameMetrics evaluateFrame(const std::vector<TruePlane>& true_planes, const std::vector<int>& visible_points,
                           int min_visible_points, const std::vector<EvaluatedPlane>& detections,
                           const MatchTolerance& tolerance = MatchTolerance());

}  // namespace hough_plane_detector
