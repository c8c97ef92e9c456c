// The continuous plane detector of Hulik et al. 2014, one stage per file along the paper's
// pipeline: frame normals (normal_estimator), voting and blur (hough_voting), peak search
// (hough_peaks), per-frame fitting and its planarity tests (frame_planes, planarity_tests,
// block_regions), the parallel-plane search (parallel_planes), the persistent map with its
// thinning, ids, extents and evidence (plane_map), and the frame's labels (frame_labels).
// PlaneDetector runs them in order on each frame and times each.
//
// Errors, throughout the core: what can fail on input returns bool, false with the reason in a
// `std::string* error` (which may be null) and nothing changed. Only the constructor throws, for
// parameters its caller did not validate first (a programming error, not bad input).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/detected_plane.h"
#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/frame_data.h"
#include "hough_plane_detector/core/frame_labels.h"
#include "hough_plane_detector/core/frame_planes.h"
#include "hough_plane_detector/core/hough_parameterization.h"
#include "hough_plane_detector/core/hough_peaks.h"
#include "hough_plane_detector/core/hough_voting.h"
#include "hough_plane_detector/core/planarity_tests.h"
#include "hough_plane_detector/core/plane_map.h"
#include "hough_plane_detector/core/thread_team.h"
#include "hough_plane_detector/core/sparse_hough_space.h"

namespace hough_plane_detector
{

struct StageTimings
{
  double normals_ms = 0;   // windows' normals and the blocks' sums
  double blocks_ms = 0;    // the blocks' statistics with voting, blur and peaks beside them (wall time of the four)
  double voting_ms = 0;    // cache space
  double blur_ms = 0;      // local space
  double peaks_ms = 0;     // local peaks
  double fit_ms = 0;       // per-frame planes from the peaks (windows or block regions)
  double parallel_ms = 0;  // the parallel-plane search
  double evidence_ms = 0;  // forgetting by evidence: the map's planes checked against the frame (beside the fits)
  double global_ms = 0;    // the map: thinning, accumulation, global peaks, ids
  double labels_ms = 0;    // the frame's labels, support and extents
  double total_ms = 0;
};

struct MemoryReport
{
  size_t global_bytes = 0;      // top grid + allocated chunks of the persistent space
  size_t global_chunks = 0;
  size_t local_bytes = 0;       // per-frame space, as allocated in the last frame
  size_t local_pooled_bytes = 0;  // its freed chunks kept for the next frame's (16 MB at most)
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
  // Precondition: params.validate(); throws std::invalid_argument naming the problem otherwise.
  explicit PlaneDetector(const DetectorParams& params);
  // The stages keep references to the detector's own parameters and frame: it stays where it
  // was built (hold it by std::unique_ptr to move it).
  PlaneDetector(const PlaneDetector&) = delete;
  PlaneDetector& operator=(const PlaneDetector&) = delete;

  // Adds one organized frame; returns false (map untouched) with `error` set on bad input.
  bool processFrame(const CloudView& cloud, const Eigen::Isometry3d& camera_to_world, double stamp,
                    std::string* error = nullptr);

  const std::vector<DetectedPlane>& planes() const { return map_.planes(); }
  const StageTimings& lastTimings() const { return timings_; }
  const FrameStats& lastStats() const { return stats_; }
  // The depth noise model of the last frame (sensor_model, sensor_noise, focal length read
  // from the cloud).
  const DepthNoiseModel& noiseModel() const { return frame_.noise; }
  // Every local peak of the last frame that was tested as a plane, strongest first.
  const std::vector<PlaneCandidate>& lastCandidates() const { return candidates_; }
  // The accepted planes of the last frame, as voted into the map (world frame).
  const std::vector<FramePlane>& lastFramePlanes() const { return frame_planes_; }
  // The last frame as the stages measured it (blocks, windows, noise, pose).
  const FrameData& lastFrame() const { return frame_; }
  MemoryReport memory() const;
  const DetectorParams& params() const { return params_; }
  const HoughParameterization& parameterization() const { return param_; }
  const SparseHoughSpace& globalSpace() const { return map_.space(); }
  const PlaneMap& map() const { return map_; }

  // Planar windows of the last frame and the id of the plane each lies on (-1: none).
  const std::vector<WindowSample>& lastSamples() const { return frame_.samples; }
  const std::vector<int>& lastSampleLabels() const { return labels_.samples; }
  // Plane id of every stride x stride pixel block of the last frame (-1: none), row-major over
  // normalEstimator().blocksX() x blocksY(); a block is labelled when its points lie on the plane.
  const std::vector<int>& lastBlockLabels() const { return labels_.blocks; }
  const NormalEstimator& normalEstimator() const { return frame_.normals; }
  // Plane id of every pixel of the last frame (-1: none): pixels of a labelled block that lie
  // within support_distance of its plane. `cloud` must be the last frame's cloud.
  void labelPixels(const CloudView& cloud, std::vector<int>& labels) const;
  // Where the plane has been seen (nullptr for an unknown id).
  const PlaneExtent* extent(int id) const;
  // Convex hull of the plane's extent in the world frame (empty when it has none).
  std::vector<Eigen::Vector3d> hull(const DetectedPlane& plane) const;
  // Convex hull of each connected region of the plane's extent, largest first (PlaneExtent::regions).
  std::vector<std::vector<Eigen::Vector3d>> regions(const DetectedPlane& plane) const;
  // The shape of each connected region: concave outline, holes, fill (PlaneExtent::outlines).
  std::vector<PlaneOutline> outlines(const DetectedPlane& plane) const;

  // Parameters that keep the Hough grid (everything but resolution, angle_step, d_step,
  // max_distance, blur_kernel_size, peak_window) change in place; returns false, changing
  // nothing, when the new ones need a new detector (and an empty map) or are invalid.
  bool updateParams(const DetectorParams& params, std::string* error);
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
  void estimateNormals(const CloudView& cloud);
  void findLocalPeaks(std::vector<HoughPeak>& peaks);

  DetectorParams params_;
  HoughParameterization param_;
  HoughVoting voting_;
  HoughPeakSearch peak_search_;
  SparseHoughSpace local_;
  FrameData frame_;
  std::unique_ptr<ThreadTeam> measurement_team_;  // measurement_threads members
  PlanarityTests tests_;
  FramePlaneFitter fitter_;
  PlaneMap map_;
  FrameLabels labels_;
  std::vector<FramePlane> frame_planes_;  // accepted per-frame planes of the last frame
  std::vector<PlaneCandidate> candidates_;
  StageTimings timings_;
  FrameStats stats_;
  double focal_length_ = 0.0;  // px at 640 wide, from the clouds (0: the sensor's nominal one)
  PinholeIntrinsics intrinsics_;  // of the last cloud that showed them
};

}  // namespace hough_plane_detector
