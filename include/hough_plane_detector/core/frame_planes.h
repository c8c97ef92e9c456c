// Per-frame planes (paper 3.5): each local Hough peak is fitted to the frame's points that
// agree with it, by the paper's windows or by block regions grown from it, and kept when
// the planarity tests pass; a plane a few degrees off a known one may take its normal.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "hough_plane_detector/core/detected_plane.h"
#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/frame_data.h"
#include "hough_plane_detector/core/hough_parameterization.h"
#include "hough_plane_detector/core/hough_peaks.h"
#include "hough_plane_detector/core/planarity_tests.h"

namespace hough_plane_detector
{

// What became of a local Hough peak of the last frame: why a plane in view was not detected.
enum class CandidateVerdict
{
  kAccepted,           // a per-frame plane, voted into the map
  kTooFewPoints,       // fewer than min_support points lie on it (windows, then blocks)
  kCurvedPatches,      // its connected patches are curved (halves tilt apart) or tiny
  kCentroidsOffPlane,  // block centroids scatter more than the sensor noise allows (chi^2)
  kHalvesDisagree,     // the fits of its two halves differ by more than merge_angle
  kNotParallel,        // parallel search: its blocks' own fit is not parallel to the known plane
  kEdgeOn,             // region: most rays graze its plane, which their depths cannot test
  kNormalUndetermined,  // its points fix its normal no better than merge_angle / 3 (1 sigma), and no known normal fits
};
const char* toString(CandidateVerdict verdict);

struct PlaneCandidate
{
  Eigen::Vector3d normal;  // world frame, after the last refit
  double d;
  double peak_value;       // blurred local Hough value of its peak; 0 for the parallel search
  double points;           // points on it when it was accepted or refused (0: too few windows)
  CandidateVerdict verdict;
  bool parallel_search = false;  // a cluster of the parallel search, not a Hough peak
};

// An accepted plane of the frame, world frame.
struct FramePlane
{
  Eigen::Vector3d hough = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double d = 0.0;
  double value = 0.0;     // its local peak's value; 0 for the parallel search and leftover regions
  double support = 0.0;   // points of the frame on it
  bool parallel = false;  // with a known plane's normal: the parallel search's, or snapped to it
  double first_sight_points = 0.0;  // support with near points weighted by precision (strong_support)
  // Where it was measured (world frame): its points' centroid and the standard error of its
  // offset there; 0 when unknown (the parallel search's planes).
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double offset_sigma = 0.0;
  // The standard error of its normal (rad) from its blocks; 0 when unknown.
  double normal_sigma = 0.0;
  // Its normal was constrained level (FramePlaneFitter::uprightFace): normal_sigma is then the
  // standard error of its turn about the vertical.
  bool upright = false;
  // Its blocks lie on it within their noise and its interior's own plane agrees with it: a
  // region leaning over a fold or a curve fails (the first-sight report, plane_map.cpp). A
  // snapped plane is judged on the blocks the snap measured it with.
  bool fits_its_blocks = false;
  // Snapped onto the vertical with the world's up known: its normal is gravity's, which keeps
  // level surfaces parallel, not its blocks' (FramePlaneFitter::regionPlane).
  bool level_snap = false;
  // A level snap whose blocks fit its offset but have no interior to test: one frame may report
  // it (first sight). It is not a measurement that keeps a map plane out of view
  // (measuresOneSurface): without an interior its blocks cannot show a curve.
  bool level_strip = false;
  // Its blocks' centroids lie off it beyond their noise (p = 0.01, noiseBoundOfMeanChi2): it
  // took blocks of another surface or bends, so it does not vote (plane_map.cpp).
  bool mixes_surfaces = false;
  std::vector<int> blocks;  // region_growing: the blocks of its region
  // Snapped: the normal the blocks that measured it fit by themselves (world frame, on the side
  // of `normal`) and its information (1/rad^2), so that the map can test over frames whether
  // the known normal explains them (PlaneMap::reseatRefutedSnaps); zero otherwise.
  Eigen::Vector3d own_normal = Eigen::Vector3d::Zero();
  Eigen::Matrix3d own_normal_information = Eigen::Matrix3d::Zero();

  // A measurement of one surface: a region that fits its blocks, or a plane measured without
  // blocks (the parallel search's, tested cluster by cluster; the paper's windows). The map keeps
  // a plane out of view only once such a measurement has supported it (PlaneBelief), a snapped
  // one only when precise (PlaneMap::vouchesForOneSurface).
  bool measuresOneSurface() const { return fits_its_blocks || blocks.empty(); }
};

class FramePlaneFitter
{
public:
  FramePlaneFitter(const DetectorParams& params, const HoughParameterization& param, FrameData& frame,
                   const PlanarityTests& tests);
  FramePlaneFitter(const FramePlaneFitter&) = delete;  // holds references to its owner's state
  FramePlaneFitter& operator=(const FramePlaneFitter&) = delete;

  // The paper's fit, strongest peak first: each peak takes the windows that agree with it and
  // no earlier plane took and their blocks, refitted until they no longer change. A plane may snap
  // to the normal of one of `map_planes`. Fills frame.block_claim.
  void fitWindows(const std::vector<HoughPeak>& peaks, const std::vector<DetectedPlane>& map_planes,
                  std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates);
  // region_growing: each peak seeds block regions grown on their refitted planes; then the
  // flat blocks left seed regions of their own.
  void growRegions(const std::vector<HoughPeak>& peaks, const std::vector<DetectedPlane>& map_planes,
                   std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates);
  // Camera-frame moments of the blocks under `windows` (indices into frame.samples) that lie
  // on the world plane (normal, d) and no plane of this frame claimed. `tight` (around a
  // fitted plane) also drops blocks farther off than their own noise allows.
  PointMoments collectPlaneBlocks(const Eigen::Vector3d& normal, double d, const std::vector<int>& windows,
                                  std::vector<int>& blocks, bool tight = false);
  // Gives an accepted plane within snap_angle of a known plane (the map's, or this frame's in
  // `planes`) that normal, and the offset its blocks agree on, when most of its points lie
  // on that parallel plane within their noise and the likelihood-ratio test allows (and, with
  // the world's up unknown and another surface's normal, a grown region's own scatter too:
  // NormalExplanation::interior_within_own_scatter, as acceptsKnownNormal asks with up known
  // of normals off the vertical). True if it did; then `measured_by`, when given, holds the
  // blocks on that plane that measured its offset. A region `seen_edge_on` is judged by the
  // share of its blocks' depth noise along the known normal (the ray's sine of it).
  bool snapToKnownDirection(Eigen::Vector3d& normal, double& d, const std::vector<int>& blocks,
                            const std::vector<DetectedPlane>& map_planes, const std::vector<FramePlane>& planes,
                            std::vector<int>* measured_by = nullptr, bool seen_edge_on = false) const;

private:
  // The paper's refinement: up to three passes of taking the unclaimed windows near the
  // plane, their blocks on it, and refitting. The verdict when it ran out of points.
  CandidateVerdict refineOnWindows(const std::vector<char>& claimed, Eigen::Vector3d& normal, double& d,
                                   std::vector<int>& windows, std::vector<int>& blocks, PointMoments& moments,
                                   PointMoments& weighted);
  // The planarity tests of a grown region, in order; the flat components' moments in `moments`.
  CandidateVerdict testRegion(const BlockRegionGrower& grower, PlaneRegion& region, PointMoments& moments) const;
  // A region whose blocks lie off its plane beyond their noise, split into two connected parts
  // that each lie on their own plane within it; false when no such split exists.
  bool splitMixedRegion(const BlockRegionGrower& grower, const PlaneRegion& region, std::vector<int>& first,
                        std::vector<int>& second) const;
  // Sets the plane's centroid and offset error from the blocks that measured it.
  void describeMeasurement(FramePlane& plane, const std::vector<int>& blocks) const;
  // A snapped plane's own_normal and its information, from the blocks that measured it.
  void recordOwnNormal(FramePlane& plane, const std::vector<int>& measured_by) const;
  // FramePlane::fits_its_blocks, level_strip and mixes_surfaces: how the blocks' centroids, and
  // the interior's own plane, agree with (normal, d) within the sensor's noise.
  void testFitToBlocks(FramePlane& plane, const std::vector<int>& blocks) const;
  // A region's accepted plane (world frame) as the map receives it; normal_sigma is
  // PlanarityTests::normalUncertainty of its blocks, which the caller has already computed.
  // Its fit is tested on `measured_by`: the blocks, or for a snapped plane the snap's.
  FramePlane regionPlane(const Eigen::Vector3d& normal, double d, double value, double support, bool parallel,
                         const std::vector<int>& blocks, double normal_sigma,
                         const std::vector<int>& measured_by, bool upright = false) const;
  // Joins touching regions of this frame that the region tests accept as one plane, but not the
  // two parts of a split region (split_group_).
  void mergeTouchingRegions(const BlockRegionGrower& grower, std::vector<FramePlane>& planes);
  // True when the normal's standard error (normalUncertainty of the blocks) is at most
  // merge_angle / 2: within merge_angle at two sigmas.
  bool normalDetermined(double normal_sigma) const;
  // A face of undetermined normal refitted upright (world_z_up): its world plane and the
  // uncertainty of its turn about the vertical, when it fits upright and that turn is determined.
  bool uprightFace(const std::vector<int>& blocks, Eigen::Vector3d& normal, double& d, double& normal_sigma) const;
  // The normal of a known plane (the map's, or this frame's) within snap_angle of `normal`: of
  // the closest in angle that passes within merge_distance of `centroid` (world frame), the
  // piece's, if any, else of the closest; nullptr when none is within snap_angle.
  // `on_that_plane`, when given: whether the normal is of a plane the piece lies on.
  const Eigen::Vector3d* knownNormalFor(const Eigen::Vector3d& normal, const Eigen::Vector3d& centroid,
                                        const std::vector<DetectedPlane>& map_planes,
                                        const std::vector<FramePlane>& planes, bool* on_that_plane = nullptr) const;

  const DetectorParams& params_;
  const HoughParameterization& param_;
  FrameData& frame_;
  const PlanarityTests& tests_;
  BlockMarks collected_;  // scratch of collectPlaneBlocks
  // Per plane of growRegions' `planes`: the number of the split region it is a part of, or -1.
  std::vector<int> split_group_;
};

}  // namespace hough_plane_detector
