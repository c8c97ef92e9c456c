#include "hough_plane_detector/core/plane_detector.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <unordered_set>

#include <Eigen/Eigenvalues>

#include "hough_plane_detector/core/block_regions.h"

namespace hough_plane_detector
{

namespace
{
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

constexpr double kCentroidFloor = 0.001 * 0.001;  // pose and calibration jitter, in m^2
constexpr double kMaxMeanCentroidChi2 = 4.0;       // block centroids about a plane, per block
constexpr double kMaxParallelCentroidSigma = 0.3;  // parallel search: of support_distance
constexpr double kMinParallelGrazingSine = 0.1;    // parallel search: rays at least ~6 deg to the plane
constexpr double kMinSnapInlierShare = 0.8;        // snapping: points that must lie on the parallel plane
constexpr double kMaxSnapChi2Increase = 9.21;      // snapping: chi^2 with 2 dof, p = 0.01

// Angle between two planes' normals regardless of their sign.
double unsignedAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return std::acos(std::min(1.0, std::abs(a.dot(b))));
}

// Throws before any member is built from bad values (a zero step would size the space at infinity).
const DetectorParams& validated(const DetectorParams& params)
{
  const std::string problem = params.validate();
  if (!problem.empty()) throw std::invalid_argument("invalid detector parameters: " + problem);
  return params;
}

bool isFiniteTransform(const Eigen::Isometry3d& t)
{
  if (!t.matrix().allFinite()) return false;
  const Eigen::Matrix3d r = t.linear();
  return (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-3 && r.determinant() > 0.0;
}
}  // namespace

const char* toString(CandidateVerdict verdict)
{
  switch (verdict)
  {
    case CandidateVerdict::kAccepted: return "accepted";
    case CandidateVerdict::kTooFewPoints: return "too few points";
    case CandidateVerdict::kCurvedPatches: return "curved patches";
    case CandidateVerdict::kCentroidsOffPlane: return "centroids off the plane";
    case CandidateVerdict::kHalvesDisagree: return "halves disagree";
    case CandidateVerdict::kNotParallel: return "not parallel to the known plane";
    case CandidateVerdict::kEdgeOn: return "seen edge-on";
  }
  return "unknown";
}

PlaneDetector::PlaneDetector(const DetectorParams& params)
  : params_(validated(params))
  , param_(params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance, marginCells(params))
  , local_(param_.sizeAngle(), param_.sizeAngle(), param_.sizeD())
  , global_(param_.sizeAngle(), param_.sizeAngle(), param_.sizeD())
{
  blur_radius_ = params_.blur_kernel_size / 2;
  peak_radius_ = params_.peak_window / 2;
  // Precomputed once (paper 3.3.2); maximum 1, so a lone vote of weight w blurs to peak w.
  blur_kernel_.resize(2 * blur_radius_ + 1);
  for (int i = -blur_radius_; i <= blur_radius_; ++i)
    blur_kernel_[i + blur_radius_] = static_cast<float>(std::exp(-0.5 * i * i / (params_.blur_sigma * params_.blur_sigma)));
}

void PlaneDetector::reset()
{
  chunks_evicted_total_ = 0;
  extents_.clear();
  beliefs_.clear();
  frame_count_ = 0;
  global_.clear();
  local_.clear();
  planes_.clear();
  samples_.clear();
  candidates_.clear();
  sample_labels_.clear();
  next_id_ = 0;
}

MemoryReport PlaneDetector::memory() const
{
  MemoryReport report;
  report.global_bytes = global_.bytesUsed();
  report.global_chunks = global_.chunkCount();
  report.local_bytes = local_.bytesUsed();
  report.dense_bytes = global_.denseBytes();
  report.top_level_cells = global_.topLevelCount();
  report.chunks_evicted_total = chunks_evicted_total_;
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
  camera_to_world_ = camera_to_world;
  ++frame_count_;
  const auto frame_start = Clock::now();

  auto t = Clock::now();
  NormalEstimatorConfig normal_config;
  normal_config.window = params_.normal_window;
  normal_config.stride = params_.normal_stride;
  normal_config.min_valid_fraction = params_.min_valid_fraction;
  normal_config.max_curvature = params_.max_curvature;
  // The sensor's projection from the cloud itself (its focal length sets the disparity steps);
  // the last good estimate, or the sensor's nominal one, when this cloud cannot tell.
  const PinholeIntrinsics intrinsics = estimateIntrinsics(cloud);
  if (intrinsics.valid())
  {
    intrinsics_ = intrinsics;
    focal_length_ = intrinsics.fx * 640.0 / cloud.width;
  }
  noise_ = DepthNoiseModel(params_.sensor_model, params_.sensor_noise, focal_length_);
  normal_config.noise = noise_;
  normal_config.max_window_scale = params_.max_window_scale;
  normals_.compute(cloud, camera_to_world, normal_config, samples_);
  stats_.windows_valid = normals_.validWindows();
  stats_.samples = static_cast<int>(samples_.size());
  timings_.normals_ms = msSince(t);

  t = Clock::now();
  vote();
  timings_.voting_ms = msSince(t);

  t = Clock::now();
  blurCache();
  timings_.blur_ms = msSince(t);

  t = Clock::now();
  findLocalPeaks();
  timings_.peaks_ms = msSince(t);

  t = Clock::now();
  if (params_.forgetting == kForgetByEvidence) checkEvidence(cloud);
  timings_.evidence_ms = msSince(t);

  t = Clock::now();
  updateGlobal(camera_to_world.translation(), stamp);
  timings_.global_ms = msSince(t);
  timings_.total_ms = msSince(frame_start);
  return true;
}

void PlaneDetector::vote()
{
  votes_.clear();
  const float overlap = static_cast<float>(params_.normal_stride * params_.normal_stride) /
                        static_cast<float>(params_.normal_window * params_.normal_window);
  const uint64_t sy = global_.sizeY(), sz = global_.sizeZ();
  auto push = [&](const Eigen::Vector3d& hough, float weight) {
    const Eigen::Vector3d c = param_.toCell(hough);
    const int x = static_cast<int>(std::lround(c.x())), y = static_cast<int>(std::lround(c.y())),
              z = static_cast<int>(std::lround(c.z()));
    if (!global_.inBounds(x, y, z))
    {
      ++stats_.votes_out_of_range;
      return;
    }
    votes_.emplace_back((static_cast<uint64_t>(x) * sy + y) * sz + z, weight);
  };
  for (const WindowSample& sample : samples_)
  {
    // One vote per window weighted by its points over the window overlap, so the space
    // counts points: the paper's one vote per point with far fewer eigen solves.
    const float weight = static_cast<float>(sample.count) * overlap;
    const Eigen::Vector3d hough = param_.toHough(sample.normal, sample.d);
    push(hough, weight);
    Eigen::Vector3d mirrored;
    if (param_.mirror(hough, mirrored)) push(mirrored, weight);
  }
  // The unblurred cache space (paper 3.3.3): one entry per distinct cell.
  std::sort(votes_.begin(), votes_.end(),
            [](const std::pair<uint64_t, float>& a, const std::pair<uint64_t, float>& b) { return a.first < b.first; });
  cache_.clear();
  for (size_t i = 0; i < votes_.size();)
  {
    const uint64_t key = votes_[i].first;
    float weight = 0.0f;
    for (; i < votes_.size() && votes_[i].first == key; ++i) weight += votes_[i].second;
    const int z = static_cast<int>(key % sz), y = static_cast<int>((key / sz) % sy), x = static_cast<int>(key / (sz * sy));
    cache_.emplace_back(Eigen::Vector3i(x, y, z), weight);
  }
  stats_.cache_cells = static_cast<int>(cache_.size());
}

void PlaneDetector::blurCache()
{
  local_.clear();
  const float* k = blur_kernel_.data();
  for (const auto& entry : cache_)
    local_.addSeparable(entry.first.x(), entry.first.y(), entry.first.z(), blur_radius_, k, k, k, entry.second);
}

Eigen::Vector3i PlaneDetector::climb(const SparseHoughSpace& space, Eigen::Vector3i cell) const
{
  const int64_t sy = space.sizeY(), sz = space.sizeZ();
  auto index = [&](const Eigen::Vector3i& c) { return (static_cast<int64_t>(c.x()) * sy + c.y()) * sz + c.z(); };
  float value = space.value(cell.x(), cell.y(), cell.z());
  for (int step = 0; step < 1000; ++step)
  {
    Eigen::Vector3i best = cell;
    float best_value = value;
    int64_t best_index = index(cell);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
        {
          const Eigen::Vector3i n(cell.x() + dx, cell.y() + dy, cell.z() + dz);
          if (!space.inBounds(n.x(), n.y(), n.z())) continue;
          const float v = space.value(n.x(), n.y(), n.z());
          const int64_t i = index(n);
          if (v > best_value || (v == best_value && i < best_index))
          {
            best = n;
            best_value = v;
            best_index = i;
          }
        }
    if (best == cell) break;
    cell = best;
    value = best_value;
  }
  return cell;
}

bool PlaneDetector::isWindowMaximum(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const
{
  const int64_t sy = space.sizeY(), sz = space.sizeZ();
  const float value = space.value(cell.x(), cell.y(), cell.z());
  const int64_t own = (static_cast<int64_t>(cell.x()) * sy + cell.y()) * sz + cell.z();
  const int r = peak_radius_;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy)
      for (int dz = -r; dz <= r; ++dz)
      {
        const int x = cell.x() + dx, y = cell.y() + dy, z = cell.z() + dz;
        const float v = space.value(x, y, z);
        if (v > value) return false;
        if (v == value && v > 0.0f && (static_cast<int64_t>(x) * sy + y) * sz + z < own) return false;
      }
  return true;
}

Eigen::Vector3d PlaneDetector::subVoxelMean(const SparseHoughSpace& space, const Eigen::Vector3i& cell) const
{
  // Eq. 6: m(x) = sum h(p) p / sum h(p) over the peak window W(x).
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double total = 0.0;
  const int r = peak_radius_;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy)
      for (int dz = -r; dz <= r; ++dz)
      {
        const double v = space.value(cell.x() + dx, cell.y() + dy, cell.z() + dz);
        weighted += v * Eigen::Vector3d(dx, dy, dz);
        total += v;
      }
  return cell.cast<double>() + (total > 0.0 ? Eigen::Vector3d(weighted / total) : Eigen::Vector3d::Zero());
}

std::vector<PlaneDetector::Peak> PlaneDetector::extractPeaks(const SparseHoughSpace& space,
                                                             const std::vector<Eigen::Vector3i>& seeds,
                                                             double threshold) const
{
  std::vector<Peak> peaks;
  std::unordered_set<int64_t> visited;
  const int64_t sy = space.sizeY(), sz = space.sizeZ();
  for (const Eigen::Vector3i& seed : seeds)
  {
    const Eigen::Vector3i top = climb(space, seed);
    if (!visited.insert((static_cast<int64_t>(top.x()) * sy + top.y()) * sz + top.z()).second) continue;
    const float value = space.value(top.x(), top.y(), top.z());
    if (value < threshold || !isWindowMaximum(space, top)) continue;
    Peak peak;
    peak.hough = param_.fromCell(subVoxelMean(space, top));
    // Mirrored twins beyond the border are the same plane. A peak right on the border may
    // refine to a hair beyond it on both sides, so allow a cell; the merge joins the twins.
    if (peak.hough.head<2>().norm() > M_PI / 2 + param_.angleStep()) continue;
    param_.fromHough(peak.hough, peak.normal, peak.d);
    peak.value = value;
    peaks.push_back(peak);
  }
  return peaks;
}

std::vector<PlaneDetector::Peak> PlaneDetector::mergeSimilar(std::vector<Peak> peaks) const
{
  std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) { return a.value > b.value; });
  std::vector<Peak> merged;
  std::vector<double> weights;
  for (const Peak& peak : peaks)
  {
    bool absorbed = false;
    for (size_t i = 0; i < merged.size() && !absorbed; ++i)
    {
      Peak& m = merged[i];
      const double sign = m.normal.dot(peak.normal) >= 0.0 ? 1.0 : -1.0;
      const Eigen::Vector3d n2 = sign * peak.normal;
      const double d2 = sign * peak.d;
      // Eq. 7-8: similar when both the normal angle and the d difference are small.
      if (unsignedAngle(m.normal, n2) > params_.merge_angle || std::abs(m.d - d2) > params_.merge_distance) continue;
      // Eq. 9-10: strength-weighted mean of normal and d.
      const double w1 = weights[i], w2 = peak.value;
      m.normal = ((w1 * m.normal + w2 * n2) / (w1 + w2)).normalized();
      m.d = (w1 * m.d + w2 * d2) / (w1 + w2);
      weights[i] = w1 + w2;
      absorbed = true;
    }
    if (!absorbed)
    {
      merged.push_back(peak);
      weights.push_back(peak.value);
    }
  }
  for (Peak& m : merged) m.hough = param_.toHough(m.normal, m.d);
  return merged;
}

int PlaneDetector::bestPlaneFor(const WindowSample& sample, const std::vector<Eigen::Vector3d>& normals,
                                const std::vector<double>& ds) const
{
  const double cos_limit = std::cos(params_.support_angle);
  int best = -1;
  double best_distance = params_.support_distance;
  for (size_t i = 0; i < normals.size(); ++i)
  {
    if (std::abs(sample.normal.dot(normals[i])) < cos_limit) continue;
    const double distance = std::abs(normals[i].dot(sample.centroid) + ds[i]);
    if (distance <= best_distance)
    {
      best_distance = distance;
      best = static_cast<int>(i);
    }
  }
  return best;
}

PointMoments PlaneDetector::collectPlaneBlocks(const Eigen::Vector3d& normal, double d,
                                              const std::vector<int>& windows, std::vector<int>& blocks,
                                              bool tight)
{
  // Blocks covered by the windows, each once, whose points lie on the plane.
  const int k = params_.normal_window / blockSize(params_.normal_window, params_.normal_stride);
  const int bx_count = normals_.blocksX();
  block_mark_.resize(static_cast<size_t>(bx_count) * normals_.blocksY(), 0);
  ++mark_generation_;
  // The plane in the camera frame, to test block centroids without transforming blocks.
  const Eigen::Vector3d n_cam = camera_to_world_.linear().transpose() * normal;
  const double d_cam = d + normal.dot(camera_to_world_.translation());
  PointMoments moments;
  blocks.clear();
  for (int s : windows)
    for (int by = samples_[s].window_y; by < samples_[s].window_y + k; ++by)
      for (int bx = samples_[s].window_x; bx < samples_[s].window_x + k; ++bx)
      {
        const int b = by * bx_count + bx;
        if (block_mark_[b] == mark_generation_) continue;
        block_mark_[b] = mark_generation_;
        const BlockInfo& info = block_info_[b];
        if (!info.valid || (!block_claim_.empty() && block_claim_[b])) continue;
        const double residual = std::abs(n_cam.dot(info.centroid) + d_cam);
        // Tight: drops surfaces that merely cross the infinite plane along a line.
        if (residual > (tight ? std::min(params_.support_distance, info.tight_residual) : params_.support_distance))
          continue;
        // A block straddling an edge keeps its centroid near the plane while a few far points
        // would dominate the fit's moments: its spread along the normal must look like noise.
        if (n_cam.dot(info.covariance * n_cam) > info.thickness_limit) continue;
        moments.add(normals_.block(bx, by));
        blocks.push_back(b);
      }
  return moments;
}

bool PlaneDetector::isPlanarFit(const PointMoments& moments, const std::vector<int>& blocks) const
{
  // A curved surface (a pillar, a ball) yields planar windows and even a whole fit within the
  // sensor noise; but block centroids, where noise averages out, bend away from the fit.
  // Each must lie on it as closely as the block's own scatter allows (chi^2 per block).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(moments.covariance());
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  const Eigen::Vector3d mean = moments.mean();
  const int bx_count = normals_.blocksX();
  double chi2 = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& info = block_info_[b];
    const double count = normals_.block(b % bx_count, b / bx_count).count;
    // The block's own scatter along the plane normal: noise if it lies on the plane.
    const double own_variance = std::max(0.0, normal.dot(info.covariance * normal));
    const double step = noise_.quantizationStep(info.centroid.z());
    const double distance = normal.dot(info.centroid - mean);
    chi2 += distance * distance / (own_variance / count + step * step / 12.0 + kCentroidFloor);
  }
  if (!blocks.empty() && chi2 / blocks.size() > kMaxMeanCentroidChi2) return false;
  return true;
}


bool PlaneDetector::halvesAgree(const std::vector<int>& blocks, size_t begin, size_t end, double max_angle) const
{
  // A curved strip fits a plane within the noise, but its two halves tilt apart.
  const int bx_count = normals_.blocksX();
  PointMoments all;
  for (size_t i = begin; i < end; ++i) all.add(centroidMoments(normals_.block(blocks[i] % bx_count, blocks[i] / bx_count)));
  if (all.count < 3) return true;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(all.covariance());
  const Eigen::Vector3d mean = all.mean();
  for (int axis = 1; axis <= 2; ++axis)
  {
    const Eigen::Vector3d direction = solver.eigenvectors().col(axis);
    PointMoments halves[2];
    double half_variance[2] = {0.0, 0.0};  // mean centroid variance of each half's blocks
    int half_blocks[2] = {0, 0};
    for (size_t i = begin; i < end; ++i)
    {
      const PointMoments block = centroidMoments(normals_.block(blocks[i] % bx_count, blocks[i] / bx_count));
      const int h = direction.dot(block.mean() - mean) >= 0.0 ? 1 : 0;
      halves[h].add(block);
      half_variance[h] += block_info_[blocks[i]].centroid_variance + kCentroidFloor;
      ++half_blocks[h];
    }
    for (int h = 0; h < 2; ++h)
      if (half_blocks[h] > 0) half_variance[h] /= half_blocks[h];
    if (halves[0].count < 3 || halves[1].count < 3) continue;
    Eigen::Vector3d half_normals[2];
    double tilt_variance = 0.0;  // of the angle between the halves' normals, from their fits
    for (int h = 0; h < 2; ++h)
    {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> half_solver;
      half_solver.computeDirect(halves[h].covariance());
      half_normals[h] = half_solver.eigenvectors().col(0);
      // A fit of n centroids of noise v spread s^2 along its narrower side tilts by about
      // sqrt(v / (n s^2)); two or three blocks in a row fix no normal at all.
      const double spread = half_solver.eigenvalues()(1);
      tilt_variance += spread > 0.0 ? half_variance[h] / (half_blocks[h] * spread) : 1e9;
    }
    const double tilt = unsignedAngle(half_normals[0], half_normals[1]);
    // Windows' fit: the paper's fixed tolerance; regions: also beyond what the fits' noise explains.
    if (tilt > max_angle && (!params_.region_growing || tilt > 3.0 * std::sqrt(tilt_variance))) return false;
  }
  return true;
}

PointMoments PlaneDetector::weightedMoments(const std::vector<int>& blocks) const
{
  return weightedCentroidMoments(block_info_, blocks);
}

PointMoments PlaneDetector::keepFlatComponents(std::vector<int>& blocks, double max_angle, int min_span,
                                              const std::function<bool(const std::vector<int>&)>& also)
{
  // Two pillars can share a tangent plane: each connected patch of the support must be flat
  // on its own; curved patches are dropped, tiny ones too (they cannot be tested).
  constexpr size_t kMinComponentBlocks = 4;
  const int bx_count = normals_.blocksX(), by_count = normals_.blocksY();
  member_mark_.resize(static_cast<size_t>(bx_count) * by_count, 0);
  visit_mark_.resize(member_mark_.size(), 0);
  ++component_generation_;
  for (int b : blocks) member_mark_[b] = component_generation_;
  std::vector<int> kept, component;
  for (int seed : blocks)
  {
    if (visit_mark_[seed] == component_generation_) continue;
    component.assign(1, seed);
    visit_mark_[seed] = component_generation_;
    for (size_t head = 0; head < component.size(); ++head)
      forEachNeighbour(component[head], bx_count, by_count, [&](int nb) {
        if (member_mark_[nb] != component_generation_ || visit_mark_[nb] == component_generation_) return;
        visit_mark_[nb] = component_generation_;
        component.push_back(nb);
      });
    int x_min = bx_count, x_max = -1, y_min = by_count, y_max = -1;
    for (int b : component)
    {
      x_min = std::min(x_min, b % bx_count), x_max = std::max(x_max, b % bx_count);
      y_min = std::min(y_min, b / bx_count), y_max = std::max(y_max, b / bx_count);
    }
    const bool wide_enough = x_max - x_min + 1 >= min_span && y_max - y_min + 1 >= min_span;
    if (component.size() >= kMinComponentBlocks && wide_enough && halvesAgree(component, 0, component.size(), max_angle) &&
        (!also || also(component)))
      kept.insert(kept.end(), component.begin(), component.end());
  }
  blocks.swap(kept);
  PointMoments moments;
  for (int b : blocks) moments.add(normals_.block(b % bx_count, b / bx_count));
  return moments;
}

void PlaneDetector::findLocalPeaks()
{
  describeBlocks(normals_, params_, noise_, block_info_);
  // A peak above the threshold has voted cells next to it blurred to well over half of it
  // (the kernel falls to 0.6 one cell away); climbing from the rest only finds weak peaks.
  std::vector<Eigen::Vector3i> seeds;
  seeds.reserve(cache_.size());
  const float seed_floor = static_cast<float>(0.5 * params_.local_threshold);
  for (const auto& entry : cache_)
    if (local_.value(entry.first.x(), entry.first.y(), entry.first.z()) >= seed_floor) seeds.push_back(entry.first);
  std::vector<Peak> peaks = extractPeaks(local_, seeds, params_.local_threshold);
  // The strongest peaks are enough; a frame holds far fewer real planes than this.
  constexpr size_t kMaxLocalPeaks = 64;
  std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) { return a.value > b.value; });
  if (peaks.size() > kMaxLocalPeaks) peaks.resize(kMaxLocalPeaks);

  std::vector<Peak> supported;
  candidates_.clear();
  if (params_.region_growing)
    growRegions(peaks, supported);
  else
    fitWindowPlanes(peaks, supported);
  const auto parallel_start = Clock::now();
  findParallelPlanes(supported);
  timings_.parallel_ms = msSince(parallel_start);
  // No merge here: greedy claiming already leaves a peak's mirrored twin or echo no windows.
  local_peaks_ = supported;
  stats_.local_peaks = static_cast<int>(local_peaks_.size());
}

void PlaneDetector::fitWindowPlanes(const std::vector<Peak>& peaks, std::vector<Peak>& supported)
{
  // Greedy, strongest first: a peak takes the windows that agree with it and no earlier
  // plane took, is refined by a least-squares fit to their points, and keeps them. Weaker
  // echoes of the same plane find nothing left; refined per-frame planes that agree to a
  // fraction of a cell keep the global peaks sharp.
  std::vector<char> claimed(samples_.size(), 0);
  const double overlap = static_cast<double>(params_.normal_stride * params_.normal_stride) /
                         (params_.normal_window * params_.normal_window);
  block_claim_.assign(static_cast<size_t>(normals_.blocksX()) * normals_.blocksY(), 0);
  const double cos_limit = std::cos(params_.support_angle);
  std::vector<int> windows, blocks;
  for (const Peak& peak : peaks)
  {
    Eigen::Vector3d normal = peak.normal;
    double d = peak.d;
    PointMoments moments, weighted;  // weighted: of the final blocks, reused by the planarity test
    CandidateVerdict verdict = CandidateVerdict::kAccepted;
    for (int pass = 0; pass < 3; ++pass)
    {
      windows.clear();
      double window_points = 0.0;
      for (size_t s = 0; s < samples_.size(); ++s)
      {
        if (claimed[s] || std::abs(samples_[s].normal.dot(normal)) < cos_limit) continue;
        if (std::abs(normal.dot(samples_[s].centroid) + d) <= params_.support_distance)
        {
          windows.push_back(static_cast<int>(s));
          window_points += samples_[s].count * overlap;
        }
      }
      // Overlapping windows count their points about once each: too few, no fit needed.
      if (window_points < params_.min_support)
      {
        moments = PointMoments();
        verdict = CandidateVerdict::kTooFewPoints;
        break;
      }
      moments = collectPlaneBlocks(normal, d, windows, blocks, pass > 0);
      if (moments.count < std::max(3, params_.min_support))
      {
        verdict = CandidateVerdict::kTooFewPoints;
        break;
      }
      moments = keepFlatComponents(blocks, params_.merge_angle, 1);
      if (moments.count < std::max(3, params_.min_support))
      {
        verdict = CandidateVerdict::kCurvedPatches;
        break;
      }
      weighted = weightedMoments(blocks);
      const PointMoments world = weighted.transformed(camera_to_world_);
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(world.covariance());
      Eigen::Vector3d n = solver.eigenvectors().col(0).normalized();
      if (n.dot(normal) < 0.0) n = -n;
      const double d_new = -n.dot(world.mean());
      // Converged: another pass would select the same windows and blocks.
      const bool converged = pass > 0 && unsignedAngle(n, normal) < 2e-4 && std::abs(d_new - d) < 5e-4;
      normal = n;
      d = d_new;
      if (converged) break;
    }
    if (verdict == CandidateVerdict::kAccepted && !isPlanarFit(weighted, blocks))
      verdict = CandidateVerdict::kCentroidsOffPlane;
    else if (verdict == CandidateVerdict::kAccepted && !halvesAgree(blocks, 0, blocks.size(), params_.merge_angle))
      verdict = CandidateVerdict::kHalvesDisagree;
    const bool snapped = verdict == CandidateVerdict::kAccepted && snapToKnownDirection(normal, d, blocks, supported);
    candidates_.push_back({normal, d, peak.value, moments.count, verdict});
    if (verdict != CandidateVerdict::kAccepted) continue;
    // Claim everything within support_distance, not just the tight fit, so that leftovers
    // around an accepted plane cannot pose as a slightly tilted second one.
    for (int s : windows) claimed[s] = 1;
    for (int b : blocks) block_claim_[b] = 1;
    collectPlaneBlocks(normal, d, windows, blocks, false);
    for (int b : blocks) block_claim_[b] = 1;
    Peak refined = peak;
    refined.normal = normal;
    refined.d = d;
    refined.hough = param_.toHough(normal, d);
    refined.support = moments.count;
    refined.parallel = snapped;
    supported.push_back(refined);
  }
}

void PlaneDetector::growRegions(const std::vector<Peak>& peaks, std::vector<Peak>& supported)
{
  // Strongest first, each peak seeds regions of blocks that agree with it; each region grows
  // over the neighbouring blocks that lie on its refitted plane within their noise and is
  // kept when it is a plane by the same statistics. Blocks a kept region took are taken for
  // the weaker peaks. Then every flat block left seeds a region of its own plane: faces too
  // small for a window's vote (box sides, far shelves) are still planes of the frame.
  block_claim_.assign(block_info_.size(), 0);
  std::vector<char> tried(block_info_.size(), 0);
  BlockRegionGrower grower(normals_, block_info_, params_);
  const Eigen::Matrix3d world_to_camera = camera_to_world_.linear().transpose();
  auto consider = [&](const std::vector<int>& seed, const Eigen::Vector3d& n_cam, double d_cam, double peak_value) {
    PlaneRegion region = grower.grow(seed, n_cam, d_cam, block_claim_);
    for (int b : region.blocks) tried[b] = 1;
    for (int b : region.trimmed) tried[b] = 1;  // near this plane: no seeds of a twin
    CandidateVerdict verdict = CandidateVerdict::kAccepted;
    PointMoments moments;
    if (region.points < std::max(3, params_.min_support))
      verdict = CandidateVerdict::kTooFewPoints;
    else if ((moments = keepFlatComponents(region.blocks, params_.merge_angle, 1)).count < std::max(3, params_.min_support))
      verdict = CandidateVerdict::kCurvedPatches;
    else if (!grower.fit(region.blocks, region.normal, region.d))  // of the flat components kept
      verdict = CandidateVerdict::kTooFewPoints;
    else if (grower.seenEdgeOn(region.blocks, region.normal))
      verdict = CandidateVerdict::kEdgeOn;
    else if (grower.normalsTurn(region.blocks, region.normal))
      verdict = CandidateVerdict::kCurvedPatches;
    else if (grower.centroidsBend(region.blocks, region.normal, region.d))
      verdict = CandidateVerdict::kCurvedPatches;
    else if (!isPlanarFit(weightedMoments(region.blocks), region.blocks))
      verdict = CandidateVerdict::kCentroidsOffPlane;
    else if (!halvesAgree(region.blocks, 0, region.blocks.size(), params_.merge_angle))
      verdict = CandidateVerdict::kHalvesDisagree;
    Eigen::Vector3d normal = camera_to_world_.linear() * region.normal;
    double d = region.d - normal.dot(camera_to_world_.translation());
    const bool snapped = verdict == CandidateVerdict::kAccepted && snapToKnownDirection(normal, d, region.blocks, supported);
    candidates_.push_back({normal, d, peak_value, std::max(region.points, moments.count), verdict});
    if (verdict != CandidateVerdict::kAccepted) return;
    for (int b : region.blocks) block_claim_[b] = 1;
    Peak refined;
    refined.normal = normal;
    refined.d = d;
    refined.hough = param_.toHough(normal, d);
    refined.value = peak_value;
    refined.support = moments.count;
    refined.parallel = snapped;
    refined.blocks = region.blocks;
    supported.push_back(refined);
  };
  constexpr size_t kMinSeedBlocks = 2;
  for (const Peak& peak : peaks)
  {
    const Eigen::Vector3d n_cam = world_to_camera * peak.normal;
    const double d_cam = peak.d + peak.normal.dot(camera_to_world_.translation());
    for (const std::vector<int>& seed : grower.seedComponents(n_cam, d_cam, block_claim_))
    {
      if (seed.size() < kMinSeedBlocks) break;
      bool fresh = false;
      for (int b : seed) fresh |= !block_claim_[b] && !tried[b];
      if (fresh) consider(seed, n_cam, d_cam, peak.value);
    }
  }
  // Leftover flat blocks, most points first, each with its own plane as the first guess.
  std::vector<int> order;
  for (size_t b = 0; b < block_info_.size(); ++b)
    if (block_info_[b].planar && !block_claim_[b] && !tried[b]) order.push_back(static_cast<int>(b));
  const int bx_count = normals_.blocksX();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return normals_.block(a % bx_count, a / bx_count).count > normals_.block(b % bx_count, b / bx_count).count;
  });
  for (int b : order)
  {
    if (block_claim_[b] || tried[b]) continue;
    const BlockInfo& info = block_info_[b];
    consider({b}, info.normal, -info.normal.dot(info.centroid), 0.0);
  }
}

bool PlaneDetector::snapToKnownDirection(Eigen::Vector3d& normal, double& d, const std::vector<int>& blocks,
                                         const std::vector<Peak>& supported) const
{
  // A small or far plane nearly parallel to a known one (a stair tread to the floor, a shelf
  // top) is fitted with a tilt of a few degrees: blocks of the surfaces it meets lean on its
  // edges. If most of its points lie on a plane of the known normal within their noise, that
  // plane, with one parameter fewer, is the better model.
  const Eigen::Vector3d* closest = nullptr;
  double closest_angle = params_.snap_angle;
  auto consider = [&](const Eigen::Vector3d& known_normal) {  // an element of planes_ or supported
    const double angle = unsignedAngle(known_normal, normal);
    if (angle < closest_angle)
    {
      closest_angle = angle;
      closest = &known_normal;
    }
  };
  for (const DetectedPlane& plane : planes_) consider(plane.normal);
  for (const Peak& peak : supported) consider(peak.normal);
  if (!closest || blocks.empty()) return false;
  const Eigen::Vector3d known = closest->dot(normal) >= 0.0 ? *closest : Eigen::Vector3d(-*closest);
  const Eigen::Vector3d n_cam = camera_to_world_.linear().transpose() * known;
  // The offset most points agree on (a median: the leaning blocks are outliers), then the
  // blocks within three of their sigmas of it.
  const int bx_count = normals_.blocksX();
  auto points = [&](int b) { return normals_.block(b % bx_count, b / bx_count).count; };
  std::vector<std::pair<double, double>> offsets;  // camera-frame d of each block, its points
  double total = 0.0;
  for (int b : blocks)
  {
    offsets.emplace_back(-n_cam.dot(block_info_[b].centroid), points(b));
    total += points(b);
  }
  std::sort(offsets.begin(), offsets.end());
  double median = offsets.back().first, below = 0.0;
  for (const auto& offset : offsets)
    if ((below += offset.second) >= 0.5 * total)
    {
      median = offset.first;
      break;
    }
  std::vector<int> inliers;
  double inlier_points = 0.0, weight_sum = 0.0, weighted_d = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& info = block_info_[b];
    const double offset = -n_cam.dot(info.centroid);
    if (std::abs(offset - median) > 3.0 * std::sqrt(info.centroid_variance + kCentroidFloor)) continue;
    inliers.push_back(b);
    inlier_points += points(b);
    weight_sum += info.fit_weight;
    weighted_d += info.fit_weight * offset;
  }
  if (inlier_points < kMinSnapInlierShare * total) return false;
  const double d_cam = weighted_d / weight_sum;
  if (centroidChi2(n_cam, d_cam, inliers) > kMaxMeanCentroidChi2) return false;
  // The known normal must also explain the inliers about as well as their own best plane: a
  // likelihood-ratio test (2 degrees of freedom, the normal's), else a box face a few degrees
  // off an older box's would take its direction. Judged on the interior: rim blocks straddling
  // a fold (a ramp's foot, a tread's nosing) are the lean the snap exists to undo.
  if (!explainedByNormal(n_cam, inliers)) return false;
  normal = known;
  d = d_cam - known.dot(camera_to_world_.translation());
  return true;
}

bool PlaneDetector::explainedByNormal(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const
{
  std::vector<int> interior = interiorBlocks(blocks, normals_.blocksX(), normals_.blocksY());
  if (interior.size() < kMinInteriorBlocks) interior = blocks;
  return snapChi2Increase(n_cam, interior) <= kMaxSnapChi2Increase;
}

double PlaneDetector::snapChi2Increase(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const
{
  // Centroids weighted by their inverse variance: the smallest eigenvalue of their scatter
  // times the total weight is the chi^2 of the best free plane; the fixed normal's best plane
  // has the weighted variance of the offsets along it.
  const int bx_count = normals_.blocksX();
  PointMoments sum;
  double weight_sum = 0.0, offset_sum = 0.0, offset_squares = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& info = block_info_[b];
    const double weight = 1.0 / (info.centroid_variance + kCentroidFloor);
    PointMoments m = centroidMoments(normals_.block(b % bx_count, b / bx_count));
    m.scale(weight / m.count);
    sum.add(m);
    const double offset = n_cam.dot(info.centroid);
    weight_sum += weight;
    offset_sum += weight * offset;
    offset_squares += weight * offset * offset;
  }
  if (weight_sum <= 0.0) return 0.0;
  const double fixed_chi2 = offset_squares - offset_sum * offset_sum / weight_sum;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(sum.covariance());
  return fixed_chi2 - std::max(0.0, solver.eigenvalues()(0)) * sum.count;
}

double PlaneDetector::centroidChi2(const Eigen::Vector3d& n_cam, double d_cam, const std::vector<int>& blocks) const
{
  double chi2 = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& info = block_info_[b];
    const double distance = n_cam.dot(info.centroid) + d_cam;
    chi2 += distance * distance / (info.centroid_variance + kCentroidFloor);
  }
  return blocks.empty() ? 0.0 : chi2 / blocks.size();
}

bool PlaneDetector::fitIsParallel(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const
{
  // Far from a Kinect an 8 x 8 block is as thick as it is wide, so a band of wall blocks at one
  // height passes for a floor-parallel patch block by block; their centroids together still
  // span the wall, not a floor.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(weightedMoments(blocks).covariance());
  return unsignedAngle(solver.eigenvectors().col(0), n_cam) <= 2.0 * params_.merge_angle;
}

void PlaneDetector::findParallelPlanes(std::vector<Peak>& supported)
{
  // Stair treads and risers, shelves: narrower than a normal window, so no window lies on them
  // alone and they raise no Hough peak; but they are parallel to a floor or wall already
  // known. Along a known normal, a block's offset d is precise even where its own normal is
  // noise, so the free blocks' offsets are searched for clusters (a 1-D Hough transform).
  if (params_.parallel_support <= 0) return;
  std::vector<Eigen::Vector3d> directions;
  struct KnownPlane
  {
    Eigen::Vector3d normal, normal_cam;
    double d, d_cam;
  };
  std::vector<KnownPlane> known;  // planes a cluster must not repeat, in both frames
  auto addKnown = [&](const Eigen::Vector3d& normal, double d) {
    known.push_back({normal, camera_to_world_.linear().transpose() * normal, d,
                     d + normal.dot(camera_to_world_.translation())});
  };
  for (const Peak& peak : supported) addKnown(peak.normal, peak.d);
  for (const DetectedPlane& plane : planes_) addKnown(plane.normal, plane.d);
  for (const KnownPlane& plane : known)
  {
    bool seen = false;
    for (const Eigen::Vector3d& direction : directions) seen |= unsignedAngle(direction, plane.normal) < params_.merge_angle;
    if (!seen) directions.push_back(plane.normal);
  }

  const int count = static_cast<int>(block_info_.size());
  const int bx_count = normals_.blocksX();
  std::vector<std::pair<double, int>> offsets;  // world d of each flat free block, sorted
  std::vector<char> used;
  std::vector<int> blocks;
  for (const Eigen::Vector3d& normal : directions)
  {
    const Eigen::Vector3d n_cam = camera_to_world_.linear().transpose() * normal;
    const double shift = normal.dot(camera_to_world_.translation());  // d_world = d_cam - shift
    offsets.clear();
    for (int b = 0; b < count; ++b)
    {
      const BlockInfo& info = block_info_[b];
      if (!info.valid || block_claim_[b] || n_cam.dot(info.covariance * n_cam) > info.thickness_limit) continue;
      // A block says which side of its neighbours it lies on only if its centroid is much more
      // precise than the cluster width; and seen along the plane (grazing rays), a wall's block
      // is as thin along the normal as a floor's: there the thickness test means nothing.
      if (info.centroid_variance > kMaxParallelCentroidSigma * kMaxParallelCentroidSigma * params_.support_distance *
                                       params_.support_distance ||
          std::abs(n_cam.dot(info.centroid.normalized())) < kMinParallelGrazingSine)
        continue;
      offsets.emplace_back(-n_cam.dot(info.centroid) - shift, b);
    }
    std::sort(offsets.begin(), offsets.end());
    used.assign(offsets.size(), 0);
    auto points = [&](size_t i) { return used[i] ? 0.0 : normals_.block(offsets[i].second % bx_count, offsets[i].second / bx_count).count; };
    while (true)
    {
      // The densest interval of support_distance in d, by points.
      double best = 0.0, window = 0.0;
      size_t best_begin = 0, best_end = 0;
      for (size_t begin = 0, end = 0; begin < offsets.size(); window -= points(begin), ++begin)
      {
        for (; end < offsets.size() && offsets[end].first <= offsets[begin].first + params_.support_distance; ++end)
          window += points(end);
        if (window > best)
        {
          best = window;
          best_begin = begin;
          best_end = end;
        }
      }
      if (best < params_.parallel_support) break;
      double weight_sum = 0.0, weighted_d = 0.0;
      for (size_t i = best_begin; i < best_end; ++i)
      {
        if (used[i]) continue;
        used[i] = 1;
        weight_sum += block_info_[offsets[i].second].fit_weight;
        weighted_d += block_info_[offsets[i].second].fit_weight * offsets[i].first;
      }
      double d = weighted_d / weight_sum;
      bool repeats = false;
      for (const KnownPlane& plane : known)
      {
        const double sign = plane.normal.dot(normal) >= 0.0 ? 1.0 : -1.0;
        if (unsignedAngle(plane.normal, normal) < params_.merge_angle &&
            std::abs(d - sign * plane.d) < 2.0 * params_.merge_distance)
          repeats = true;
      }
      // Surfaces cut by a plane through the sensor all project to one image line, whose blocks
      // form that plane for any surface behind them: no plane can be seen edge-on.
      const double d_cam = d + shift;
      if (repeats || std::abs(d_cam) < 2.0 * params_.support_distance) continue;
      // Its blocks: free ones within their own noise of the cluster's plane, in patches that
      // are not curved (a pillar's front is flat along a wall's normal for a hand's width).
      // Blocks that lie on a known plane of another tilt (a floor beside a ramp) stay its own.
      blocks.clear();
      // Offsets are sorted: only those within support_distance of d can be within reach.
      const auto first = std::lower_bound(offsets.begin(), offsets.end(), std::make_pair(d - params_.support_distance, -1));
      for (auto it = first; it != offsets.end() && it->first <= d + params_.support_distance; ++it)
      {
        const auto& offset = *it;
        const BlockInfo& info = block_info_[offset.second];
        const double reach = std::min(params_.support_distance, info.tight_residual);
        if (block_claim_[offset.second] || std::abs(offset.first - d) > reach) continue;
        bool on_known = false;
        for (const KnownPlane& plane : known)
          if (std::abs(plane.normal_cam.dot(info.centroid) + plane.d_cam) <= reach) on_known = true;
        if (!on_known) blocks.push_back(offset.second);
      }
      // A strip one block wide (a pillar's tangent line) shows no curvature across it; each
      // patch must lie on the plane within its noise on its own, as others may be clutter.
      const PointMoments moments = keepFlatComponents(blocks, params_.support_angle, 2, [&](const std::vector<int>& patch) {
        return centroidChi2(n_cam, d_cam, patch) <= kMaxMeanCentroidChi2;
      });
      PlaneCandidate candidate{normal, d, 0.0, moments.count, CandidateVerdict::kAccepted, true};
      if (moments.count < params_.parallel_support)
        candidate.verdict = CandidateVerdict::kCurvedPatches;
      else if (!fitIsParallel(n_cam, blocks) || !explainedByNormal(n_cam, blocks))
        candidate.verdict = CandidateVerdict::kNotParallel;
      if (candidate.verdict == CandidateVerdict::kAccepted)
      {
        weight_sum = weighted_d = 0.0;
        for (int b : blocks)
        {
          block_claim_[b] = 1;
          weight_sum += block_info_[b].fit_weight;
          weighted_d += block_info_[b].fit_weight * (-n_cam.dot(block_info_[b].centroid) - shift);
        }
        d = candidate.d = weighted_d / weight_sum;
        Peak peak;
        peak.normal = normal;
        peak.d = d;
        peak.hough = param_.toHough(normal, d);
        peak.value = 0.0;
        peak.support = moments.count;
        peak.parallel = true;
        supported.push_back(peak);
        addKnown(normal, d);
      }
      candidates_.push_back(candidate);
    }
  }
}

void PlaneDetector::addGaussian(SparseHoughSpace& space, const Eigen::Vector3d& hough, float weight, float cap)
{
  // Centred on the sub-voxel position, so the global space keeps what eq. 6 refined.
  const Eigen::Vector3d c = param_.toCell(hough);
  const Eigen::Vector3i ci(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())),
                           static_cast<int>(std::lround(c.z())));
  const int r = blur_radius_;
  const double inv = 1.0 / (2.0 * params_.blur_sigma * params_.blur_sigma);
  float kernels[3][16];
  for (int axis = 0; axis < 3; ++axis)
  {
    const double frac = c(axis) - ci(axis);
    for (int i = -r; i <= r; ++i) kernels[axis][i + r] = static_cast<float>(std::exp(-(i - frac) * (i - frac) * inv));
  }
  space.addSeparable(ci.x(), ci.y(), ci.z(), r, kernels[0], kernels[1], kernels[2], weight, cap);
}

void PlaneDetector::updateGlobal(const Eigen::Vector3d& camera_position, double stamp)
{
  const float cap = static_cast<float>(params_.permanence_cap);
  // Thinning (3.7) first, so a plane seen in this frame ends the frame at least 1 higher. By
  // evidence, the cells of the map's planes are exempt (what is out of view keeps its state)
  // and a plane the frames showed to be gone is cleared; the rest (votes no plane
  // gathered) thins as in the paper.
  if (params_.forgetting == kForgetByEvidence)
    thinByEvidence(cap);
  else
    global_.thin(static_cast<float>(params_.thinning_rate), cap);

  // Algorithm 2: every local peak adds one Gaussian of maximum 1 to the global space. A plane
  // not yet in the map adds up to 2 when strongly supported, so that a big plane is reported the
  // first time it is seen, while known planes gain 1 per frame as in the paper (thinning and
  // permanence keep their pace). Noisier sensors need more points for the same precision: the
  // bar rises with sensor_noise^2. A plane of the parallel search, or one snapped to a known
  // normal, measured only its offset, so a quarter of the points is as strong.
  const double strong_support = params_.strong_support * std::max(1.0, params_.sensor_noise * params_.sensor_noise);
  auto inMap = [this](const Peak& peak) {
    for (const DetectedPlane& plane : planes_)
    {
      const double sign = plane.normal.dot(peak.normal) >= 0.0 ? 1.0 : -1.0;
      if (unsignedAngle(plane.normal, peak.normal) < params_.merge_angle &&
          std::abs(plane.d - sign * peak.d) < params_.merge_distance)
        return true;
    }
    return false;
  };
  std::vector<Eigen::Vector3i> seeds;
  auto cellOf = [this](const Eigen::Vector3d& hough) {
    const Eigen::Vector3d c = param_.toCell(hough);
    return Eigen::Vector3i(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())),
                           static_cast<int>(std::lround(c.z())));
  };
  for (const Peak& peak : local_peaks_)
  {
    const float weight = inMap(peak) ? 1.0f
                         : params_.strong_support > 0
                             ? static_cast<float>(1.0 + std::min(1.0, peak.support / (peak.parallel ? 0.25 * strong_support : strong_support)))
                             : 1.0f;
    addGaussian(global_, peak.hough, weight, cap);
    Eigen::Vector3d mirrored;
    if (param_.mirror(peak.hough, mirrored)) addGaussian(global_, mirrored, weight, cap);
    seeds.push_back(cellOf(peak.hough));
  }
  for (const DetectedPlane& plane : planes_) seeds.push_back(cellOf(plane.hough));
  stats_.chunks_evicted = static_cast<int>(global_.evictWeakest(static_cast<size_t>(params_.max_chunks)));
  chunks_evicted_total_ += stats_.chunks_evicted;

  std::vector<Peak> peaks = mergeSimilar(extractPeaks(global_, seeds, params_.global_threshold));

  // Stable ids: each new peak takes the id of the closest previous plane it is similar to.
  std::vector<DetectedPlane> previous;
  previous.swap(planes_);
  std::vector<bool> taken(previous.size(), false);
  for (const Peak& peak : peaks)
  {
    DetectedPlane plane;
    plane.hough = peak.hough;
    plane.strength = peak.value;
    int match = -1;
    double best_cost = 2.0;
    for (size_t i = 0; i < previous.size(); ++i)
    {
      if (taken[i]) continue;
      const double cost = unsignedAngle(previous[i].normal, peak.normal) / (2.0 * params_.merge_angle + 1e-9) +
                          std::abs(std::abs(previous[i].d) - std::abs(peak.d)) / (2.0 * params_.merge_distance + 1e-9);
      const double sign = previous[i].normal.dot(peak.normal) >= 0.0 ? 1.0 : -1.0;
      if (std::abs(previous[i].d - sign * peak.d) > 2.0 * params_.merge_distance) continue;
      if (cost < best_cost)
      {
        best_cost = cost;
        match = static_cast<int>(i);
      }
    }
    double sign;
    if (match >= 0)
    {
      taken[match] = true;
      plane.id = previous[match].id;
      plane.first_seen = previous[match].first_seen;
      plane.last_seen = previous[match].last_seen;
      sign = previous[match].normal.dot(peak.normal) >= 0.0 ? 1.0 : -1.0;  // keep the reported side
    }
    else
    {
      plane.id = next_id_++;
      plane.first_seen = stamp;
      plane.last_seen = stamp;
      sign = peak.normal.dot(camera_position) + peak.d >= 0.0 ? 1.0 : -1.0;  // face the sensor
    }
    plane.normal = sign * peak.normal;
    plane.d = sign * peak.d;
    planes_.push_back(plane);
  }

  // Beliefs follow the ids: a new plane starts at PlaneBelief::kStart, a plane that left the
  // map takes its belief with it.
  if (params_.forgetting == kForgetByEvidence)
  {
    std::unordered_map<int, PlaneBelief> beliefs;
    for (DetectedPlane& plane : planes_)
    {
      const auto it = beliefs_.find(plane.id);
      const PlaneBelief& belief = beliefs[plane.id] = it != beliefs_.end() ? it->second : PlaneBelief();
      plane.confirmations = belief.confirmations;
      plane.contradictions = belief.contradictions;
    }
    beliefs_.swap(beliefs);
  }

  // Support and labels of this frame: windows go to the plane they agree with, then their
  // blocks that lie on it count once.
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> ds;
  for (const DetectedPlane& plane : planes_)
  {
    normals.push_back(plane.normal);
    ds.push_back(plane.d);
  }
  sample_labels_.assign(samples_.size(), -1);
  std::vector<std::vector<int>> plane_windows(planes_.size());
  for (size_t s = 0; s < samples_.size(); ++s)
  {
    const int best = bestPlaneFor(samples_[s], normals, ds);
    if (best < 0) continue;
    plane_windows[best].push_back(static_cast<int>(s));
    sample_labels_[s] = planes_[best].id;
  }
  block_labels_.assign(static_cast<size_t>(normals_.blocksX()) * normals_.blocksY(), -1);
  block_claim_.clear();  // the map's planes are distinct: each takes its own windows' blocks
  for (DetectedPlane& plane : planes_) plane.support = 0;
  // A region of this frame labels its blocks with the map plane it is: its points are the
  // measured support, also where a face is too small for any window.
  if (params_.region_growing) labelRegionBlocks();
  std::vector<int> blocks;
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    if (planes_[p].support > 0) continue;
    const PointMoments moments = collectPlaneBlocks(planes_[p].normal, planes_[p].d, plane_windows[p], blocks);
    planes_[p].support = static_cast<int>(moments.count);
    for (int b : blocks) block_labels_[b] = planes_[p].id;
  }
  for (DetectedPlane& plane : planes_)
    if (plane.support >= params_.min_support) plane.last_seen = stamp;

  // Extents: this frame's labelled blocks mark their cells; cells fade like the Hough space
  // (lazily, swept every 16 frames); extents of planes that left the map go with them.
  const float fade = extentFade();
  std::unordered_map<int, PlaneExtent> extents;
  std::unordered_map<int, std::pair<PlaneExtent*, const DetectedPlane*>> by_id;
  for (const DetectedPlane& plane : planes_)
  {
    auto it = extents_.find(plane.id);
    PlaneExtent& extent = extents[plane.id];
    if (it != extents_.end()) extent = std::move(it->second);
    if (frame_count_ % 16 == 0) extent.sweep(frame_count_, fade);
    by_id.emplace(plane.id, std::make_pair(&extent, &plane));
  }
  int last_id = -1;
  const std::pair<PlaneExtent*, const DetectedPlane*>* target = nullptr;
  for (size_t b = 0; b < block_labels_.size(); ++b)
  {
    if (block_labels_[b] < 0) continue;
    if (block_labels_[b] != last_id)  // neighbouring blocks mostly share a plane
    {
      last_id = block_labels_[b];
      target = &by_id.at(last_id);
    }
    const Eigen::Vector3d centroid = camera_to_world_ * block_info_[b].centroid;
    target->first->add(centroid, target->second->normal, target->second->d, frame_count_, fade);
  }
  extents_.swap(extents);
}

void PlaneDetector::labelRegionBlocks()
{
  block_claim_.assign(block_labels_.size(), 0);
  const int bx_count = normals_.blocksX();
  for (const Peak& peak : local_peaks_)
  {
    int best = -1;
    double best_cost = 2.0;
    for (size_t p = 0; p < planes_.size(); ++p)
    {
      const double sign = planes_[p].normal.dot(peak.normal) >= 0.0 ? 1.0 : -1.0;
      const double cost = unsignedAngle(planes_[p].normal, peak.normal) / (params_.merge_angle + 1e-9) +
                          std::abs(planes_[p].d - sign * peak.d) / (params_.merge_distance + 1e-9);
      if (cost < best_cost)
      {
        best_cost = cost;
        best = static_cast<int>(p);
      }
    }
    if (best < 0) continue;
    for (int b : peak.blocks)
    {
      if (block_claim_[b]) continue;
      block_claim_[b] = 1;
      block_labels_[b] = planes_[best].id;
      planes_[best].support += static_cast<int>(normals_.block(b % bx_count, b / bx_count).count);
    }
  }
}

const PlaneExtent* PlaneDetector::extent(int id) const
{
  const auto it = extents_.find(id);
  return it == extents_.end() ? nullptr : &it->second;
}

float PlaneDetector::extentFade() const
{
  // By evidence, where a plane was seen stays known until the plane goes.
  return params_.forgetting == kForgetByEvidence ? 0.0f : static_cast<float>(params_.thinning_rate);
}

void PlaneDetector::checkEvidence(const CloudView& cloud)
{
  for (const DetectedPlane& plane : planes_)
  {
    const auto extent = extents_.find(plane.id);
    if (extent == extents_.end()) continue;
    const PlaneEvidence evidence = checkPlaneEvidence(extent->second, plane.normal, plane.d, cloud, camera_to_world_,
                                                      intrinsics_, noise_, frame_count_, extentFade());
    beliefs_[plane.id].update(evidence);
  }
}

void PlaneDetector::thinByEvidence(float cap)
{
  // The cells around each established map plane's peak (its blur and peak window, and the
  // mirrored copy near the border) are kept as they are, a gone plane's are cleared; a plane
  // not yet established thins like everything else.
  const int r = blur_radius_ + params_.peak_window / 2 + 1;
  std::vector<std::pair<Eigen::Vector3i, float>> kept;
  auto forBox = [&](const Eigen::Vector3d& hough, const std::function<void(int, int, int)>& f) {
    std::vector<Eigen::Vector3d> centres{hough};
    Eigen::Vector3d mirrored;
    if (param_.mirror(hough, mirrored)) centres.push_back(mirrored);
    for (const Eigen::Vector3d& centre : centres)
    {
      const Eigen::Vector3d c = param_.toCell(centre);
      const int cx = static_cast<int>(std::lround(c.x())), cy = static_cast<int>(std::lround(c.y())),
                cz = static_cast<int>(std::lround(c.z()));
      for (int x = cx - r; x <= cx + r; ++x)
        for (int y = cy - r; y <= cy + r; ++y)
          for (int z = cz - r; z <= cz + r; ++z) f(x, y, z);
    }
  };
  for (const DetectedPlane& plane : planes_)
  {
    const auto belief = beliefs_.find(plane.id);
    if (belief != beliefs_.end() && belief->second.gone())
      forBox(plane.hough, [&](int x, int y, int z) {
        const float v = global_.value(x, y, z);
        if (v > 0.0f) global_.add(x, y, z, -v);
      });
    else if (belief != beliefs_.end() && belief->second.established())
      forBox(plane.hough, [&](int x, int y, int z) {
        const float v = global_.value(x, y, z);
        if (v > 0.0f) kept.emplace_back(Eigen::Vector3i(x, y, z), v);
      });
  }
  global_.thin(static_cast<float>(params_.thinning_rate), cap);
  for (const auto& cell : kept)
  {
    const float now = global_.value(cell.first.x(), cell.first.y(), cell.first.z());
    if (now < cell.second) global_.add(cell.first.x(), cell.first.y(), cell.first.z(), cell.second - now);
  }
}

std::vector<std::vector<Eigen::Vector3d>> PlaneDetector::regions(const DetectedPlane& plane) const
{
  const PlaneExtent* e = extent(plane.id);
  return e ? e->regions(frame_count_, extentFade()) : std::vector<std::vector<Eigen::Vector3d>>();
}

std::vector<Eigen::Vector3d> PlaneDetector::hull(const DetectedPlane& plane) const
{
  const PlaneExtent* e = extent(plane.id);
  return e ? e->hull(frame_count_, extentFade()) : std::vector<Eigen::Vector3d>();
}

void PlaneDetector::labelPixels(const CloudView& cloud, std::vector<int>& labels) const
{
  labels.assign(cloud.size(), -1);
  const int s = blockSize(params_.normal_window, params_.normal_stride), bx_count = normals_.blocksX();
  if (block_labels_.empty() || cloud.width / s != bx_count || cloud.height / s != normals_.blocksY()) return;
  std::unordered_map<int, std::pair<Eigen::Vector3d, double>> camera_planes;
  for (const DetectedPlane& plane : planes_)
  {
    const Eigen::Vector3d n = camera_to_world_.linear().transpose() * plane.normal;
    camera_planes[plane.id] = {n, plane.d + plane.normal.dot(camera_to_world_.translation())};
  }
  for (size_t b = 0; b < block_labels_.size(); ++b)
  {
    if (block_labels_[b] < 0) continue;
    const auto& plane = camera_planes[block_labels_[b]];
    const int bx = static_cast<int>(b) % bx_count, by = static_cast<int>(b) / bx_count;
    for (int v = by * s; v < (by + 1) * s; ++v)
      for (int u = bx * s; u < (bx + 1) * s; ++u)
      {
        float x, y, z;
        cloud.point(u, v, x, y, z);
        if (std::isfinite(x + y + z) &&
            std::abs(plane.first.dot(Eigen::Vector3d(x, y, z)) + plane.second) <= params_.support_distance)
          labels[static_cast<size_t>(v) * cloud.width + u] = block_labels_[b];
      }
  }
}

bool PlaneDetector::sameGrid(const DetectorParams& a, const DetectorParams& b)
{
  return a.effectiveAngleStep() == b.effectiveAngleStep() && a.effectiveDStep() == b.effectiveDStep() &&
         a.max_distance == b.max_distance && a.blur_kernel_size == b.blur_kernel_size && a.peak_window == b.peak_window;
}

bool PlaneDetector::updateParams(const DetectorParams& params, std::string* why)
{
  const std::string problem = params.validate();
  if (!problem.empty())
  {
    if (why) *why = problem;
    return false;
  }
  if (!sameGrid(params, params_))
  {
    if (why) *why = "the Hough grid changes";
    return false;
  }
  params_ = params;
  for (int i = -blur_radius_; i <= blur_radius_; ++i)
    blur_kernel_[i + blur_radius_] = static_cast<float>(std::exp(-0.5 * i * i / (params_.blur_sigma * params_.blur_sigma)));
  return true;
}

}  // namespace hough_plane_detector
