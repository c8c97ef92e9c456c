// Statistical tests of a set of the frame's blocks against a plane, each against the noise
// the sensor has at the blocks' depths: do the centroids lie on one plane, do its halves
// agree, does a given normal explain them as well as their own fit.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/frame_data.h"
#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{

constexpr double kCentroidFloor = 0.001 * 0.001;  // pose and calibration jitter, in m^2
constexpr double kMaxMeanCentroidChi2 = 4.0;       // block centroids about a plane, per block
constexpr double kMaxSnapChi2Increase = 9.21;      // a known normal's fit: chi^2 with 2 dof, p = 0.01

// The value an F statistic with (2, dof) degrees of freedom exceeds with probability p: its
// tail is (1 + 2 F / dof)^(-dof / 2), so this is exact.
inline double fCriticalTwo(double dof, double p)
{
  return dof / 2.0 * (std::pow(p, -2.0 / dof) - 1.0);
}

class PlanarityTests
{
public:
  PlanarityTests(const DetectorParams& params, const FrameData& frame);
  PlanarityTests(const PlanarityTests&) = delete;  // holds references to its owner's state
  PlanarityTests& operator=(const PlanarityTests&) = delete;

  // True when the block centroids of a fitted plane scatter no more than the sensor's noise.
  bool isPlanarFit(const PointMoments& moments, const std::vector<int>& blocks) const;
  // True when the fits of the two halves of blocks[begin, end) agree within max_angle (and,
  // for block regions, within what the halves' noise explains, or bowing by no more than
  // max_sag over the blocks' width). The windows (region_growing 0) never reach max_sag; its
  // default 0, any bend the noise shows, is the parallel search's, where pillars are the risk.
  bool halvesAgree(const std::vector<int>& blocks, size_t begin, size_t end, double max_angle,
                   double max_sag = 0.0) const;
  // Drops the connected patches of `blocks` that are tiny, narrower than min_span blocks
  // across the image, whose halves tilt apart by more than max_angle (curved; halvesAgree with
  // max_sag) or that fail `also`; moments of the rest, and in `kept` how many patches are left.
  PointMoments keepFlatComponents(std::vector<int>& blocks, double max_angle, int min_span,
                                  const std::function<bool(const std::vector<int>&)>& also = nullptr,
                                  int* kept = nullptr, double max_sag = 0.0) const;
  // `interior`: a plane of the camera-frame normal explains the blocks (their interior when it
  // has kMinInteriorBlocks: rim blocks may straddle a fold) about as well as their own best
  // plane: a likelihood-ratio test, chi^2 increase below kMaxSnapChi2Increase.
  // The same test, and (`with_rim`, only when the interior passes) made again with the rim
  // blocks whose own normal is informative and within its tolerance of the plane's: one
  // straddling a fold would show the fold in its normal.
  // `interior_within_own_scatter`: the same interior judged against the scatter its own best
  // plane leaves (an F test, p = 0.01) instead of the noise model, which rendered and smooth
  // faces undercut several times: there a face turned a few degrees from the known one still
  // passes the model's test. True where that scatter says nothing: no interior (the rim's lean
  // is what a snap undoes) or an interior within one block row or column (any plane fits it).
  struct NormalExplanation
  {
    bool interior = false;
    bool with_oriented_rim = false;
    bool interior_within_own_scatter = false;
  };
  NormalExplanation explainNormal(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks, bool with_rim) const;
  // Whether a plane may take the known world normal `explained` was made for (a snap, a
  // parallel cluster): its interior's verdict, and with the world's up known (world_z_up), for
  // a grown region and a normal more than 26 deg off the vertical, its own scatter's too.
  bool acceptsKnownNormal(const NormalExplanation& explained, const Eigen::Vector3d& known_normal) const
  {
    const bool judged_on_own_scatter =
        params_.world_z_up && params_.region_growing && !isLevelSurfaceNormal(known_normal);
    return explained.interior && (!judged_on_own_scatter || explained.interior_within_own_scatter);
  }
  // How much more chi^2 the block centroids have about their best plane of the camera-frame
  // normal than about their own best plane (both with the centroids' noise).
  double snapChi2Increase(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const
  {
    const SnapChi2 chi2 = snapChi2(n_cam, blocks);
    return chi2.fixed - chi2.free;
  }
  // Both chi^2 values: about the best plane of the given normal and about their own best plane.
  struct SnapChi2
  {
    double fixed = 0.0;
    double free = 0.0;
  };
  SnapChi2 snapChi2(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const;
  // The blocks' own best plane with the centroids' noise (of their interior, as explainNormal
  // judges them) and the information (1/rad^2, camera frame) it carries about its normal: a
  // tilt t of that normal raises their chi^2 by t' information t. False under 3 blocks.
  struct OwnNormal
  {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  };
  bool ownNormal(const std::vector<int>& blocks, OwnNormal& own) const;
  // blockThinAlong (block_regions.h) of one of the frame's blocks.
  bool isThinAlong(int block, const Eigen::Vector3d& n_cam) const;
  // A block centroid's variance about its true plane (its noise and kCentroidFloor), and its inverse.
  double centroidVariance(int block) const { return frame_.blocks[block].centroid_variance + kCentroidFloor; }
  double centroidWeight(int block) const { return 1.0 / centroidVariance(block); }
  // Mean chi^2 of the block centroids about a camera-frame plane.
  double centroidChi2(const Eigen::Vector3d& n_cam, double d_cam, const std::vector<int>& blocks) const;
  // True when the blocks' own fit is within 2 merge_angle of the camera-frame normal.
  bool fitIsParallel(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const;
  // Standard error (rad) of the normal the blocks' centroids fit, about the axis it is least
  // sure of: 1 / sqrt(sum of w x^2) over the weighted centroids' spread across that axis. A
  // strip of blocks along one image row fixes no tilt about its own length.
  double normalUncertainty(const std::vector<int>& blocks) const;
  // A face whose points cannot orient it, constrained to stand upright (walls, doors, the
  // sides of boxes standing on a floor): the blocks' best plane whose normal is perpendicular
  // to the camera-frame `up`, toward the sensor, with the uncertainty of its one free angle,
  // the turn about the vertical. Only when their long axis is nearer level than upright (the
  // turn they leave free is then the one the constraint fixes) and they lie on that plane
  // within their noise (mean chi^2 within noiseBoundOfMeanChi2; not against their own best
  // plane, which for a row of blocks is the plane through the sensor that depth errors along
  // the rays leave them on). False otherwise.
  bool uprightNormal(const std::vector<int>& blocks, const Eigen::Vector3d& up, Eigen::Vector3d& n_cam, double& d_cam,
                     double& sigma) const;
  // The blocks' points, each nearer than kStrongSupportDepth counted (sigma there / sigma at
  // its depth)^2 times: as many points there would measure the plane as precisely.
  double firstSightPoints(const std::vector<int>& blocks) const;
  // Moments of the blocks' centroids, each weighted by the inverse variance of the sensor at its depth.
  PointMoments weightedMoments(const std::vector<int>& blocks) const;

private:
  // Moments of the block centroids, each weighted by its inverse centroid variance (count: the weight sum).
  PointMoments noiseWeightedCentroids(const std::vector<int>& blocks) const;
  void addNoiseWeightedCentroid(int block, double weight, PointMoments& sum) const;
  // snapChi2's running sums, so that a test of more blocks goes on from a test of fewer.
  struct SnapSums
  {
    PointMoments centroids;  // noiseWeightedCentroids
    double weight = 0.0, offset = 0.0, offset_squares = 0.0;
  };
  // Adds blocks[first..] to `sums`, in order (the same sums as over the whole list at once).
  void addToSnapSums(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks, size_t first, SnapSums& sums) const;
  static SnapChi2 snapChi2Of(const SnapSums& sums);
  // The standard error (rad) of a plane's turn that the weighted centroids' spread along
  // `axis` (in the plane) fixes, about their weighted `mean`; the most informative tenth left out.
  double tiltUncertainty(const std::vector<int>& blocks, const Eigen::Vector3d& mean, const Eigen::Vector3d& axis) const;

  const DetectorParams& params_;
  const FrameData& frame_;
  mutable BlockComponents components_;  // scratch of keepFlatComponents
};

}  // namespace hough_plane_detector
