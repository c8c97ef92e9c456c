// The persistent map (paper 3.6-3.7, Alg. 2): the global Hough space every frame's planes
// vote into, its thinning, its peaks as planes with stable ids, where each plane has been
// seen (extents) and, when forgetting by evidence, how far the frames confirm it. Map files
// serialise exactly this.
#pragma once

#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/detected_plane.h"
#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/frame_data.h"
#include "hough_plane_detector/core/frame_planes.h"
#include "hough_plane_detector/core/hough_peaks.h"
#include "hough_plane_detector/core/hough_voting.h"
#include "hough_plane_detector/core/plane_evidence.h"
#include "hough_plane_detector/core/plane_extent.h"
#include "hough_plane_detector/core/sparse_hough_space.h"

namespace hough_plane_detector
{

// A map plane's snapped measurements so far (world frame): their own normals' information
// and its product with their tilts off the plane's normal, summed over viewpoints, each
// viewpoint's frames averaged into one (a still camera repeats its systematic error); and
// the centroids they measured.
struct SnapTilts
{
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Vector3d weighted_tilt = Eigen::Vector3d::Zero();
  Eigen::Matrix3d viewpoint_information = Eigen::Matrix3d::Zero();  // the current viewpoint's frames, summed
  Eigen::Vector3d viewpoint_weighted_tilt = Eigen::Vector3d::Zero();
  int64_t viewpoint_frames = 0;  // 64 bits: a still camera's frames count up for as long as it runs
  int64_t last_frame = -1;
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();  // camera position of the current viewpoint
  Eigen::Vector3d centroid_sum = Eigen::Vector3d::Zero();
  int64_t measurements = 0;
};

// How a frame's plane voted (PlaneMap::voteWeight): as a re-measurement of a map plane, as a
// complete measurement of a new surface (reported at first sight), or why it was not one.
enum class FirstSight
{
  kKnownPlane,             // on a map plane within the merge tolerances: weight 1
  kMixesSurfaces,          // its blocks lie off it beyond their noise: weight 0
  kPartOfMeasuredSurface,  // does not fit its blocks, centred on a larger surface: weight 0
  kTooSmall,               // too few points for the curvature tests: weight 1
  kComplete,               // fits its blocks, precise, no map plane near: weight 2
  kWithoutBlocks,          // by support alone (1 to 2), since: measured without blocks to test
  kNotFittingItsBlocks,    //   ... its blocks do not pass the noise tests of a plane
  kImprecise,              //   ... a second measurement could fall beyond the merge tolerances
  kNearKnownPlane,         //   ... it may be a map plane near it measured badly
};
const char* toString(FirstSight first_sight);

class PlaneMap
{
public:
  // `params` is read at every call (reconfigure changes it in place); the grid, the voting's
  // kernel and the peak search are the detector's.
  PlaneMap(const DetectorParams& params, const HoughParameterization& param, const HoughVoting& voting,
           const HoughPeakSearch& peak_search);
  PlaneMap(const PlaneMap&) = delete;  // holds references to its owner's state
  PlaneMap& operator=(const PlaneMap&) = delete;

  // Counts the frame (extents and evidence age by frames).
  void beginFrame() { ++frame_count_; }
  // Forgetting by evidence: each plane's belief from this frame's depths over its extent.
  void checkEvidence(const CloudView& cloud, const Eigen::Isometry3d& camera_to_world,
                     const PinholeIntrinsics& intrinsics, const DepthNoiseModel& noise);
  // A map plane's belief (forgetting by evidence); null for an id without one.
  const PlaneBelief* belief(int id) const
  {
    const auto it = beliefs_.find(id);
    return it == beliefs_.end() ? nullptr : &it->second;
  }
  // Alg. 2: thins the space, adds one Gaussian per frame plane (up to 2 for a strong plane not
  // yet in the map), caps the chunks, and makes the space's peaks the map's planes, each
  // keeping the id of the previous plane it continues. Returns the chunks the cap evicted.
  int accumulate(const std::vector<FramePlane>& frame_planes, const Eigen::Vector3d& camera_position, double stamp);
  // This frame's measured support of each plane (index of planes()) and its labelled blocks
  // (plane ids over frame's block grid): sets support and last_seen and grows the extents.
  void observe(const std::vector<int>& support, const std::vector<int>& block_labels, const FrameData& frame,
               double stamp);

  const std::vector<DetectedPlane>& planes() const { return planes_; }
  // How each plane of the last accumulate's frame voted (same order as its frame planes).
  const std::vector<FirstSight>& lastFirstSights() const { return first_sights_; }
  const SparseHoughSpace& space() const { return global_; }
  size_t chunksEvictedTotal() const { return chunks_evicted_total_; }
  // Map planes with snapped measurements pooled (reseatRefutedSnaps).
  size_t snapTiltRecords() const { return snap_tilts_.size(); }
  // Where the plane has been seen (nullptr for an unknown id).
  const PlaneExtent* extent(int id) const;
  std::vector<Eigen::Vector3d> hull(const DetectedPlane& plane) const;
  std::vector<std::vector<Eigen::Vector3d>> regions(const DetectedPlane& plane) const;
  std::vector<PlaneOutline> outlines(const DetectedPlane& plane) const;
  void clear();

  // Versioned bytes with the grid they were built on and a checksum (map_file.cpp).
  std::string serialize() const;
  // Replaces the state; on any problem returns false with `error` set and changes nothing.
  bool deserialize(const std::string& bytes, std::string* error);
  static std::string withChecksum(const std::string& bytes);

private:
  // Thinning (3.7); by evidence, the cells of established planes are spared, gone planes' cleared, and
  // tentative planes none of `frame_planes` measures again fade by PlaneBelief::kTentativeFade.
  void thin(float cap, const std::vector<FramePlane>& frame_planes);
  void thinByEvidence(float cap, const std::vector<FramePlane>& frame_planes);
  // True when the frame's plane lies on the map's within the merge tolerances (either side).
  bool samePlane(const DetectedPlane& known, const FramePlane& measured) const;
  // True when the map plane lies within three merge tolerances of the frame's plane, its offset
  // judged at the frame plane's centroid when known: more likely a noisy re-measurement of it
  // than a new surface.
  bool nearPlane(const DetectedPlane& known, const FramePlane& measured) const;
  // True when a map plane is near the frame's plane (nearPlane) and passes its points within
  // their offset noise and a face's warp, so the frame's plane may be that plane measured badly
  // and is not reported at first sight. Map planes flagged in `dropped` (this frame superseded
  // them) do not count: the measurement is what replaced them.
  bool nearKnownPlane(const FramePlane& measured, const std::vector<char>& dropped) const;
  // True when the frame's plane is precise enough that a second measurement of it falls within
  // the merge tolerances of it: its normal, and its offset at its own points. A level snap's
  // (FramePlane::level_snap) normal is gravity's: its offset alone is judged.
  bool preciseAtFirstSight(const FramePlane& measured) const;
  // The same, with a snapped plane's normal judged by every new surface of the frame that took
  // the same known direction (sharedDirectionSigma): a staircase's risers, a shelf's boards.
  bool preciseAtFirstSight(const FramePlane& measured, const std::vector<FramePlane>& frame_planes) const;
  // True when `region`, which does not fit its blocks, is centred on the plane of a larger
  // region of this frame that does (within kSurfaceWarp) and turned less than kCreaseAngle
  // but beyond the merge tolerances from it: a part of that surface, not a surface of its own.
  bool partOfMeasuredSurface(const FramePlane& region, const std::vector<FramePlane>& frame_planes) const;
  // The standard error (rad) of the direction that the snapped new planes of `frame_planes`
  // sharing `snapped`'s known normal measure together: their own normals pooled by their
  // information, when they agree with that normal and with each other (chi^2, p = 0.01).
  // Infinity when they do not, or when `snapped` is alone.
  double sharedDirectionSigma(const FramePlane& snapped, const std::vector<FramePlane>& frame_planes) const;
  // Clears the cells of one-frame planes this frame measured again elsewhere, nearby; flags
  // them, by index of planes_.
  std::vector<char> dropSuperseded(const std::vector<FramePlane>& frame_planes);
  // Zeroes the cells forPeakCells visits.
  void clearPeakCells(const Eigen::Vector3d& hough);
  // Calls f on every cell of the peak window and blur around `hough` (and its mirrored copy).
  void forPeakCells(const Eigen::Vector3d& hough, const std::function<void(int, int, int)>& f) const;
  // The map plane (index of planes_) a frame's plane re-measures: the closest within the merge
  // tolerances (samePlane), or -1 when none is.
  int remeasuredPlane(const FramePlane& measured) const;
  // True when one of this frame's planes lies on `plane` within the merge tolerances.
  bool remeasured(const DetectedPlane& plane, const std::vector<FramePlane>& frame_planes) const;
  // True when `measured` tells that one surface lies on its plane (PlaneBelief's
  // one_surface_measurements): it measures one surface (FramePlane::measuresOneSurface) and, if
  // snapped, its blocks could check the direction it took (preciseAtFirstSight).
  bool vouchesForOneSurface(const FramePlane& measured, const std::vector<FramePlane>& frame_planes) const;
  // Two surfaces closer than a peak window share one maximum: when this frame measured them
  // apart, or the map held them apart and depths confirmed them, the maximum's peak moves to
  // one of them and each other gets a peak at its own place (this frame's, else the map's).
  // `seed_tops`: the cell each frame plane, then each map plane, climbed to in this space.
  void addCloseSurfacePeaks(const std::vector<FramePlane>& frame_planes, const std::vector<Eigen::Vector3i>& seed_tops,
                            std::vector<HoughPeak>& peaks) const;
  // True when this frame's planes, or the map's, lie one near each peak: two surfaces.
  bool measuredApart(const HoughPeak& a, const HoughPeak& b, const std::vector<FramePlane>& frame_planes) const;
  // True when two planes one frame measured are two surfaces: not similar by eq. 7-8, or their
  // centroids lie farther apart along their normal than their offsets' errors and a face's warp allow.
  bool distinctSurfaces(const FramePlane& a, const FramePlane& b) const;
  // What a frame plane adds to the space: 1, or up to 2 when strong and not yet in the map
  // (the planes flagged in `dropped` are no longer in it); `first_sight` says which case.
  float voteWeight(const FramePlane& plane, const std::vector<FramePlane>& frame_planes,
                   const std::vector<char>& dropped, FirstSight& first_sight) const;
  // The space's peaks as the new plane list, ids carried over from the closest previous plane.
  void matchIds(const std::vector<HoughPeak>& peaks, const Eigen::Vector3d& camera_position, double stamp);
  // Beliefs follow the ids: new planes start afresh, planes that left the map take theirs along.
  void carryBeliefs();
  // Each map plane that one of this frame's planes vouches for as one surface (PlaneBelief).
  void countOneSurfaceMeasurements(const std::vector<FramePlane>& frame_planes);
  // How fast extents fade per frame: with thinning as the Hough space does, by evidence never.
  float extentFade() const;
  // A snapped measurement took a known normal its blocks may only nearly fit (a box front 2 deg
  // off the wall behind it), and the map plane it makes keeps that normal. Each frame's own fit
  // tilts from it by noise, or by that error every time: the tilts are pooled per map plane, and
  // a plane they refute together (chi^2, 2 dof, p = 0.001) moves to their own normal through
  // the centroids they measured, keeping its votes and id.
  void reseatRefutedSnaps(const std::vector<FramePlane>& frame_planes, const Eigen::Vector3d& camera_position);
  // How far apart two planes are in merge tolerances (angle / merge_angle + offset / merge_distance).
  double mergeCost(const Eigen::Vector3d& normal_a, double d_a, const Eigen::Vector3d& normal_b, double d_b) const;
  // The same for any two planes or peaks (members normal and d).
  template <class A, class B>
  double mergeCost(const A& a, const B& b) const
  {
    return mergeCost(a.normal, a.d, b.normal, b.d);
  }
  // One Gaussian vote at `hough`, and at its mirrored copy near the border.
  void addVote(const Eigen::Vector3d& hough, float weight, float cap);
  // Calls f on the cells forPeakCells visits around planes_[index] that lie nearer its peak
  // than any other plane's: a neighbour's votes are not its own, however close the two lie.
  void forOwnPeakCells(size_t index, const std::function<void(int, int, int)>& f) const;
  // Zeroes the cells forOwnPeakCells visits.
  void clearOwnPeakCells(size_t index);

  const DetectorParams& params_;
  const HoughParameterization& param_;
  const HoughVoting& voting_;
  const HoughPeakSearch& peak_search_;
  SparseHoughSpace global_;
  std::vector<DetectedPlane> planes_;
  std::unordered_map<int, PlaneExtent> extents_;
  std::unordered_map<int, PlaneBelief> beliefs_;  // forgetting by evidence, by plane id
  std::unordered_map<int, SnapTilts> snap_tilts_;  // by plane id
  std::vector<FirstSight> first_sights_;           // of the last accumulate's frame planes
  int64_t frame_count_ = 0;          // frames since the map began (extents fade by it)
  size_t chunks_evicted_total_ = 0;  // chunks freed by the max_chunks cap since the map began
  int next_id_ = 0;
};

}  // namespace hough_plane_detector
