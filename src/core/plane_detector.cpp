#include "hough_plane_detector/core/plane_detector.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "hough_plane_detector/core/parallel_planes.h"

namespace hough_plane_detector
{

namespace
{
// The per-frame space keeps up to this many freed chunks (16 KB each) for the next frame, above
// what a VGA frame uses (the bench tour: 214 at the median, 663 at most): chunks handed back to
// the system would fault their pages in again on every frame.
constexpr size_t kLocalPooledChunks = 1024;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start)
{
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

int marginCells(const DetectorParams& p)
{
  // Enough mirrored cells that blur, peak window and sub-voxel mean never see a cut border.
  return p.blur_kernel_size / 2 + p.peak_window / 2 + 2;
}

// Throws before any member is built from bad values (a zero step would size the space at infinity).
const DetectorParams& validated(const DetectorParams& params)
{
  std::string problem;
  if (!params.validate(&problem)) throw std::invalid_argument("invalid detector parameters: " + problem);
  return params;
}

bool isFiniteTransform(const Eigen::Isometry3d& t)
{
  if (!t.matrix().allFinite()) return false;
  const Eigen::Matrix3d r = t.linear();
  return (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-3 && r.determinant() > 0.0;
}
}  // namespace

PlaneDetector::PlaneDetector(const DetectorParams& params)
  : params_(validated(params))
  , param_(params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance, marginCells(params))
  , voting_(param_, params.blur_kernel_size / 2, params.blur_sigma)
  , peak_search_(param_, params.peak_window / 2)
  , local_(param_.sizeAngle(), param_.sizeAngle(), param_.sizeD(), kLocalPooledChunks)
  , measurement_team_(std::make_unique<ThreadTeam>(params.measurement_threads))
  , tests_(params_, frame_)
  , fitter_(params_, param_, frame_, tests_)
  , map_(params_, param_, voting_, peak_search_)
{
}

void PlaneDetector::reset()
{
  map_.clear();
  local_.clear();
  frame_.samples.clear();
  candidates_.clear();
  labels_.samples.clear();
}

MemoryReport PlaneDetector::memory() const
{
  MemoryReport report;
  report.global_bytes = map_.space().bytesUsed();
  report.global_chunks = map_.space().chunkCount();
  report.local_bytes = local_.bytesUsed();
  report.local_pooled_bytes = local_.bytesPooled();
  report.dense_bytes = map_.space().denseBytes();
  report.top_level_cells = map_.space().topLevelCount();
  report.chunks_evicted_total = map_.chunksEvictedTotal();
  return report;
}

bool PlaneDetector::processFrame(const CloudView& cloud, const Eigen::Isometry3d& camera_to_world, double stamp,
                                 std::string* error)
{
  auto fail = [error](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (!cloud.data || cloud.width <= 0 || cloud.height <= 0) return fail("cloud is empty");
  if (!isFiniteTransform(camera_to_world)) return fail("camera-to-world transform is not a finite rigid transform");
  if (!std::isfinite(stamp)) return fail("stamp is not finite");
  if (cloud.height == 1)
    return fail("cloud is unorganized (height 1, width " + std::to_string(cloud.width) +
                "): normals come from image windows, so an organized depth cloud (width x height) is needed");
  if (cloud.width < params_.normal_window || cloud.height < params_.normal_window)
    return fail("cloud of " + std::to_string(cloud.width) + " x " + std::to_string(cloud.height) +
                " is smaller than one normal window of " + std::to_string(params_.normal_window) + " pixels");

  timings_ = StageTimings();
  stats_ = FrameStats();
  frame_.camera_to_world = camera_to_world;
  map_.beginFrame();
  const auto frame_start = Clock::now();
  // Each stage in the paper's order, timed under its own name.
  auto timed = [](double& ms, const auto& stage) {
    const auto start = Clock::now();
    stage();
    ms = msSince(start);
  };
  timed(timings_.normals_ms, [&] { estimateNormals(cloud); });
  // Stages that read disjoint data share the team: the blocks' statistics (row by row) beside
  // voting, blur and peaks, then the evidence check beside the fits. A helper takes the Hough
  // stages, so that the blocks the fits read next are mostly described in the caller's cache.
  std::vector<HoughPeak> peaks;
  frame_.sizeBlocks();
  std::atomic<int> next_row{0};
  std::atomic<bool> hough_taken{false};
  auto describeRows = [&] {
    for (int row = next_row++; row < frame_.blocksY(); row = next_row++) frame_.describeBlockRow(params_, row);
  };
  auto houghStages = [&] {
    timed(timings_.voting_ms, [&] {
      // One vote per window weighted by its points over the window overlap.
      const float overlap = static_cast<float>(params_.normal_stride * params_.normal_stride) /
                            static_cast<float>(params_.normal_window * params_.normal_window);
      stats_.votes_out_of_range = voting_.vote(frame_.samples, overlap, local_);
      stats_.cache_cells = static_cast<int>(voting_.cache().size());
    });
    timed(timings_.blur_ms, [&] { voting_.blur(local_); });
    timed(timings_.peaks_ms, [&] { findLocalPeaks(peaks); });
  };
  timed(timings_.blocks_ms, [&] {
    // The caller alone takes both items in turn: the second then runs the Hough stages.
    measurement_team_->forEach(2, [&](int item, int member) {
      if ((member != 0 || item == 1) && !hough_taken.exchange(true)) houghStages();
      describeRows();
    });
  });
  frame_planes_.clear();
  candidates_.clear();
  measurement_team_->forEach(2, [&](int item, int) {
    if (item == 1)
    {
      timed(timings_.evidence_ms, [&] {
        if (params_.forgetting == kForgetByEvidence)
          map_.checkEvidence(cloud, camera_to_world, intrinsics_, frame_.noise);
      });
      return;
    }
    timed(timings_.fit_ms, [&] {
      if (params_.region_growing)
        fitter_.growRegions(peaks, map_.planes(), frame_planes_, candidates_);
      else
        fitter_.fitWindows(peaks, map_.planes(), frame_planes_, candidates_);
    });
    timed(timings_.parallel_ms, [&] {
      findParallelPlanes(params_, param_, frame_, tests_, map_.planes(), frame_planes_, candidates_);
    });
  });
  // No merge of the frame's planes: greedy claiming leaves a peak's mirrored twin or echo nothing.
  stats_.local_peaks = static_cast<int>(frame_planes_.size());
  timed(timings_.global_ms, [&] {
    stats_.chunks_evicted = map_.accumulate(frame_planes_, camera_to_world.translation(), stamp);
  });
  timed(timings_.labels_ms, [&] {
    labelFrame(params_, frame_, fitter_, frame_planes_, map_.planes(), labels_);
    map_.observe(labels_.support, labels_.blocks, frame_, stamp);
  });
  timings_.total_ms = msSince(frame_start);
  return true;
}

void PlaneDetector::estimateNormals(const CloudView& cloud)
{
  // The sensor's projection from the cloud itself (its focal length sets the disparity steps);
  // the last good estimate, or the sensor's nominal one, when this cloud cannot tell.
  const PinholeIntrinsics intrinsics = estimateIntrinsics(cloud);
  if (intrinsics.valid())
  {
    intrinsics_ = intrinsics;
    focal_length_ = intrinsics.fx * 640.0 / cloud.width;
  }
  frame_.measureWindows(cloud, frame_.camera_to_world, params_,
                        DepthNoiseModel(params_.sensor_model, params_.sensor_noise, focal_length_), *measurement_team_);
  stats_.windows_valid = frame_.normals.validWindows();
  stats_.samples = static_cast<int>(frame_.samples.size());
}

void PlaneDetector::findLocalPeaks(std::vector<HoughPeak>& peaks)
{
  // A peak above the threshold has voted cells next to it blurred to well over half of it
  // (the kernel falls to 0.6 one cell away); climbing from the rest only finds weak peaks.
  std::vector<Eigen::Vector3i> seeds;
  seeds.reserve(voting_.cache().size());
  const float seed_floor = static_cast<float>(0.5 * params_.local_threshold);
  for (const auto& entry : voting_.cache())
    if (local_.value(entry.first.x(), entry.first.y(), entry.first.z()) >= seed_floor) seeds.push_back(entry.first);
  peaks = peak_search_.extract(local_, seeds, params_.local_threshold);
  // The strongest peaks are enough; a frame holds far fewer real planes than this.
  constexpr size_t kMaxLocalPeaks = 64;
  std::sort(peaks.begin(), peaks.end(), [](const HoughPeak& a, const HoughPeak& b) { return a.value > b.value; });
  if (peaks.size() > kMaxLocalPeaks) peaks.resize(kMaxLocalPeaks);
}

const PlaneExtent* PlaneDetector::extent(int id) const { return map_.extent(id); }

std::vector<std::vector<Eigen::Vector3d>> PlaneDetector::regions(const DetectedPlane& plane) const
{
  return map_.regions(plane);
}

std::vector<PlaneOutline> PlaneDetector::outlines(const DetectedPlane& plane) const { return map_.outlines(plane); }

std::vector<Eigen::Vector3d> PlaneDetector::hull(const DetectedPlane& plane) const { return map_.hull(plane); }

void PlaneDetector::labelPixels(const CloudView& cloud, std::vector<int>& labels) const
{
  hough_plane_detector::labelPixels(cloud, frame_, labels_.blocks, map_.planes(), params_, labels);
}

bool PlaneDetector::sameGrid(const DetectorParams& a, const DetectorParams& b)
{
  return a.effectiveAngleStep() == b.effectiveAngleStep() && a.effectiveDStep() == b.effectiveDStep() &&
         a.max_distance == b.max_distance && a.blur_kernel_size == b.blur_kernel_size && a.peak_window == b.peak_window;
}

bool PlaneDetector::updateParams(const DetectorParams& params, std::string* error)
{
  if (!params.validate(error)) return false;
  if (!sameGrid(params, params_))
  {
    if (error) *error = "the Hough grid changes";
    return false;
  }
  params_ = params;
  voting_.setBlurSigma(params_.blur_sigma);
  if (measurement_team_->size() != params_.measurement_threads)
    measurement_team_ = std::make_unique<ThreadTeam>(params_.measurement_threads);
  return true;
}

}  // namespace hough_plane_detector
