// The continuous plane detector of Hulik et al. 2014: per-frame voting into a cache space,
// Gaussian blur, local peaks, and a persistent global Hough space with thinning (Alg. 1-2).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hough_plane_detector/core/block_regions.h"
#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/hough_parameterization.h"
#include "hough_plane_detector/core/normal_estimator.h"
#include "hough_plane_detector/core/plane_evidence.h"
#include "hough_plane_detector/core/plane_extent.h"
#include "hough_plane_detector/core/sparse_hough_space.h"

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

struct StageTimings
{
  double normals_ms = 0, voting_ms = 0, blur_ms = 0, peaks_ms = 0, global_ms = 0, total_ms = 0;
  double parallel_ms = 0;  // the parallel search, part of peaks_ms
  double evidence_ms = 0;  // forgetting by evidence: the map's planes checked against the frame
};

struct MemoryReport
{
  size_t global_bytes = 0;      // top grid + allocated chunks of the persistent space
  size_t global_chunks = 0;
  size_t local_bytes = 0;       // per-frame space, as allocated in the last frame
  size_t dense_bytes = 0;       // a dense float array of the same grid
  size_t top_level_cells = 0;
  size_t chunks_evicted_total = 0;  // freed by the max_chunks cap since the map began
};

struct FrameStats
{
  int windows_valid = 0;     // windows with enough valid points
  int samples = 0;           // planar windows that voted
  int votes_out_of_range = 0;
  int cache_cells = 0;       // distinct cells of the unblurred cache space
  int local_peaks = 0;       // local peaks kept for the global space
  int chunks_evicted = 0;    // global chunks freed by the max_chunks cap in this frame
};

class PlaneDetector
{
public:
  // Throws std::invalid_argument naming the problem when params.validate() fails.
  explicit PlaneDetector(const DetectorParams& params);

  // Adds one organized frame; returns false (map untouched) with `error` set on bad input.
  bool processFrame(const CloudView& cloud, const Eigen::Isometry3d& camera_to_world, double stamp,
                    std::string* error = nullptr);

  const std::vector<DetectedPlane>& planes() const { return planes_; }
  const StageTimings& lastTimings() const { return timings_; }
  const FrameStats& lastStats() const { return stats_; }
  // The depth noise model of the last frame (sensor_model, sensor_noise, focal length read
  // from the cloud).
  const DepthNoiseModel& noiseModel() const { return noise_; }
  // Every local peak of the last frame that was tested as a plane, strongest first.
  const std::vector<PlaneCandidate>& lastCandidates() const { return candidates_; }
  MemoryReport memory() const;
  const DetectorParams& params() const { return params_; }
  const HoughParameterization& parameterization() const { return param_; }
  const SparseHoughSpace& globalSpace() const { return global_; }

  // Planar windows of the last frame and the id of the plane each lies on (-1: none).
  const std::vector<WindowSample>& lastSamples() const { return samples_; }
  const std::vector<int>& lastSampleLabels() const { return sample_labels_; }
  // Plane id of every stride x stride pixel block of the last frame (-1: none), row-major over
  // normalEstimator().blocksX() x blocksY(); a block is labelled when its points lie on the plane.
  const std::vector<int>& lastBlockLabels() const { return block_labels_; }
  const NormalEstimator& normalEstimator() const { return normals_; }
  // Plane id of every pixel of the last frame (-1: none): pixels of a labelled block that lie
  // within support_distance of its plane. `cloud` must be the last frame's cloud.
  void labelPixels(const CloudView& cloud, std::vector<int>& labels) const;
  // Where the plane has been seen (nullptr for an unknown id).
  const PlaneExtent* extent(int id) const;
  // Convex hull of the plane's extent in the world frame (empty when it has none).
  std::vector<Eigen::Vector3d> hull(const DetectedPlane& plane) const;
  // Convex hull of each connected region of the plane's extent, largest first (PlaneExtent::regions).
  std::vector<std::vector<Eigen::Vector3d>> regions(const DetectedPlane& plane) const;

  // Parameters that keep the Hough grid (everything but resolution, angle_step, d_step,
  // max_distance, blur_kernel_size, peak_window) change in place; returns false, changing
  // nothing, when the new ones need a new detector (and an empty map) or are invalid.
  bool updateParams(const DetectorParams& params, std::string* why);
  static bool sameGrid(const DetectorParams& a, const DetectorParams& b);

  // Forgets every plane and empties the global space.
  void reset();

  // The whole persistent state (global space, planes, next id) as bytes: versioned, with the
  // grid it was built on and a checksum.
  std::string serializeMap() const;
  // Replaces the state by a serialized one; on any problem (foreign or truncated data, wrong
  // version or checksum, another grid) returns false with `error` set and changes nothing.
  bool deserializeMap(const std::string& bytes, std::string* error);
  // `bytes` with the checksum a map file ends with appended (for tools and fuzzing).
  static std::string withMapChecksum(const std::string& bytes);
  // File versions: saving writes FILE.tmp and renames it, so a crash never leaves half a map.
  bool saveMap(const std::string& path, std::string* error) const;
  bool loadMap(const std::string& path, std::string* error);

private:
  struct Peak
  {
    Eigen::Vector3d hough;
    Eigen::Vector3d normal;
    double d;
    double value;
    double support = 0.0;  // points of the frame on the refined per-frame plane
    bool parallel = false;  // with a known plane's normal: the parallel search's, or snapped to it
    std::vector<int> blocks;  // region_growing: the blocks of its region
  };

  void vote();
  void blurCache();
  void findLocalPeaks();
  // The paper's per-frame fit: each peak takes the windows that agree with it and their blocks.
  void fitWindowPlanes(const std::vector<Peak>& peaks, std::vector<Peak>& supported);
  // region_growing: each peak seeds block regions grown on their refitted planes; then the
  // flat blocks left seed regions of their own.
  void growRegions(const std::vector<Peak>& peaks, std::vector<Peak>& supported);
  // region_growing: labels each accepted region's blocks with the map plane it matches, whose
  // support they become; blocks taken this way are claimed for the windows' labelling after it.
  void labelRegionBlocks();
  void updateGlobal(const Eigen::Vector3d& camera_position, double stamp);
  // forgetting by evidence: each map plane's belief from this frame's depths over its extent.
  void checkEvidence(const CloudView& cloud);
  // forgetting by evidence: thinning that spares the map planes' cells and clears gone planes'.
  void thinByEvidence(float cap);
  // How fast extents fade per frame: with thinning as the Hough space does, by evidence never.
  float extentFade() const;
  // Climbs from a cell to the local maximum under the (value, -index) total order.
  Eigen::Vector3i climb(const SparseHoughSpace& space, Eigen::Vector3i cell) const;
  bool isWindowMaximum(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const;
  Eigen::Vector3d subVoxelMean(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const;
  std::vector<Peak> extractPeaks(const SparseHoughSpace& space, const std::vector<Eigen::Vector3i>& seeds,
                                 double threshold) const;
  std::vector<Peak> mergeSimilar(std::vector<Peak> peaks) const;
  // Index of the plane a window lies on, or -1; sign-invariant.
  int bestPlaneFor(const WindowSample& sample, const std::vector<Eigen::Vector3d>& normals,
                   const std::vector<double>& ds) const;
  // Camera-frame moments of the blocks under `windows` that lie on the world plane (normal, d).
  // `tight` (around a fitted plane) also drops blocks farther off than their own noise allows.
  PointMoments collectPlaneBlocks(const Eigen::Vector3d& normal, double d, const std::vector<int>& windows,
                                  std::vector<int>& blocks, bool tight = false);
  // True when the block centroids of a fitted plane scatter no more than the sensor's noise.
  bool isPlanarFit(const PointMoments& moments, const std::vector<int>& blocks) const;
  // True when the fits of the two halves of blocks[begin, end) agree within max_angle.
  bool halvesAgree(const std::vector<int>& blocks, size_t begin, size_t end, double max_angle) const;
  // Planes parallel to this frame's or the map's planes, among the blocks no plane took.
  void findParallelPlanes(std::vector<Peak>& supported);
  // True when the blocks' own fit is within 2 merge_angle of the camera-frame normal.
  bool fitIsParallel(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const;
  // Gives an accepted plane within snap_angle of a known plane (the map's or this frame's)
  // that normal, and the offset its blocks agree on, when most of its points lie on that
  // parallel plane within their noise. True if it did.
  bool snapToKnownDirection(Eigen::Vector3d& normal, double& d, const std::vector<int>& blocks,
                            const std::vector<Peak>& supported) const;
  // True when a plane of the camera-frame normal explains the blocks (their interior when it
  // has kMinInteriorBlocks: rim blocks may straddle a fold) about as well as their own best
  // plane: a likelihood-ratio test, chi^2 increase below kMaxSnapChi2Increase (2 dof, p = 0.01).
  bool explainedByNormal(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const;
  // How much more chi^2 the block centroids have about their best plane of the camera-frame
  // normal than about their own best plane (both with the centroids' noise).
  double snapChi2Increase(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const;
  // Mean chi^2 of the block centroids about a camera-frame plane of fixed normal.
  double centroidChi2(const Eigen::Vector3d& n_cam, double d_cam, const std::vector<int>& blocks) const;
  // Moments of the blocks, each weighted by the inverse variance of the sensor at its depth.
  PointMoments weightedMoments(const std::vector<int>& blocks) const;
  // Drops the connected patches of `blocks` that are tiny, narrower than min_span blocks across
  // the image, whose halves tilt apart by more than max_angle (curved) or that fail `also`;
  // moments of the rest.
  PointMoments keepFlatComponents(std::vector<int>& blocks, double max_angle, int min_span,
                                  const std::function<bool(const std::vector<int>&)>& also = nullptr);
  void addGaussian(SparseHoughSpace& space, const Eigen::Vector3d& hough, float weight, float cap);

  DetectorParams params_;
  HoughParameterization param_;
  NormalEstimator normals_;
  SparseHoughSpace local_;
  SparseHoughSpace global_;
  std::vector<float> blur_kernel_;
  int blur_radius_;
  int peak_radius_;

  Eigen::Isometry3d camera_to_world_ = Eigen::Isometry3d::Identity();  // of the frame in progress
  std::vector<WindowSample> samples_;
  std::vector<int> sample_labels_;
  std::vector<int> block_labels_;
  std::vector<BlockInfo> block_info_;
  std::vector<int> block_mark_;
  int mark_generation_ = 0;
  std::vector<char> block_claim_;  // blocks taken by an earlier local plane of this frame
  std::vector<int> member_mark_;
  std::vector<int> visit_mark_;
  int component_generation_ = 0;
  std::vector<std::pair<uint64_t, float>> votes_;
  std::vector<std::pair<Eigen::Vector3i, float>> cache_;
  std::vector<Peak> local_peaks_;
  std::vector<PlaneCandidate> candidates_;
  std::vector<DetectedPlane> planes_;
  std::unordered_map<int, PlaneExtent> extents_;
  std::unordered_map<int, PlaneBelief> beliefs_;  // forgetting by evidence, by plane id
  int64_t frame_count_ = 0;           // frames processed since the map began (extents fade by it)
  size_t chunks_evicted_total_ = 0;  // chunks freed by the max_chunks cap since the map began
  int next_id_ = 0;
  StageTimings timings_;
  FrameStats stats_;
  double focal_length_ = 0.0;  // px at 640 wide, from the clouds (0: the sensor's nominal one)
  PinholeIntrinsics intrinsics_;  // of the last cloud that showed them
  DepthNoiseModel noise_;      // the sensor's, for the last frame
};

}  // namespace hough_plane_detector
