#include "hough_plane_detector/core/parallel_planes.h"

#include <algorithm>
#include <cmath>

#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{

namespace
{
constexpr double kMaxParallelCentroidSigma = 0.3;  // of support_distance
constexpr double kMinParallelGrazingSine = 0.1;    // rays at least ~6 deg to the plane

struct KnownPlane
{
  Eigen::Vector3d normal, normal_cam;
  double d, d_cam;
  bool in_map;  // a map plane not yet seen in this frame: a cluster on it confirms it
};

// The search along one known direction at a time; the known planes grow as clusters are accepted.
class ParallelSearch
{
public:
  ParallelSearch(const DetectorParams& params, const HoughParameterization& param, FrameData& frame,
                 const PlanarityTests& tests, std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates)
    : params_(params), param_(param), frame_(frame), tests_(tests), planes_(planes), candidates_(candidates)
  {
  }

  void addKnown(const Eigen::Vector3d& normal, double d, bool in_map)
  {
    known_.push_back({normal, frame_.normalInCamera(normal), d, frame_.dInCamera(normal, d), in_map});
  }

  // The known planes' normals, each direction once.
  std::vector<Eigen::Vector3d> directions() const
  {
    std::vector<Eigen::Vector3d> directions;
    for (const KnownPlane& plane : known_)
    {
      bool seen = false;
      for (const Eigen::Vector3d& direction : directions) seen |= unsignedAngle(direction, plane.normal) < params_.merge_angle;
      if (!seen) directions.push_back(plane.normal);
    }
    return directions;
  }

  void searchAlong(const Eigen::Vector3d& normal)
  {
    normal_ = normal;
    n_cam_ = frame_.normalInCamera(normal);
    shift_ = normal.dot(frame_.camera_to_world.translation());  // d_world = d_cam - shift
    collectOffsets();
    double d;
    while (nextCluster(d))
    {
      // Surfaces cut by a plane through the sensor all project to one image line, whose blocks
      // form that plane for any surface behind them: no plane can be seen edge-on.
      if (repeatsAFramePlane(d) || std::abs(d + shift_) < 2.0 * params_.support_distance) continue;
      testCluster(d);
    }
  }

private:
  double points(size_t i) const { return used_[i] ? 0.0 : offset_points_[i]; }

  void collectOffsets()
  {
    offsets_.clear();
    for (int b = 0; b < static_cast<int>(frame_.blocks.size()); ++b)
    {
      const BlockInfo& info = frame_.blocks[b];
      if (!info.valid || frame_.block_claim[b]) continue;
      // A block says which side of its neighbours it lies on only if its centroid is much more
      // precise than the cluster width; and seen along the plane (grazing rays), a wall's block
      // is as thin along the normal as a floor's: there the thickness test means nothing.
      if (info.centroid_variance > kMaxParallelCentroidSigma * kMaxParallelCentroidSigma * params_.support_distance *
                                       params_.support_distance ||
          std::abs(n_cam_.dot(info.ray)) < kMinParallelGrazingSine)
        continue;
      // A block across an edge (a tread's front row holding the riser's top) is no measurement
      // of one surface: its centroid would pull a cluster off its plane.
      if (!tests_.isThinAlong(b, n_cam_)) continue;
      offsets_.emplace_back(-n_cam_.dot(info.centroid) - shift_, b);
    }
    std::sort(offsets_.begin(), offsets_.end());
    used_.assign(offsets_.size(), 0);
    offset_points_.resize(offsets_.size());
    for (size_t i = 0; i < offsets_.size(); ++i) offset_points_[i] = frame_.points(offsets_[i].second);
  }

  // The densest interval of support_distance in d, by points, its offset at the mode; false
  // when it has fewer than parallel_support points. Its offsets are used up.
  bool nextCluster(double& d)
  {
    double best = 0.0, window = 0.0;
    size_t best_begin = 0, best_end = 0;
    for (size_t begin = 0, end = 0; begin < offsets_.size(); window -= points(begin), ++begin)
    {
      for (; end < offsets_.size() && offsets_[end].first <= offsets_[begin].first + params_.support_distance; ++end)
        window += points(end);
      if (window > best)
      {
        best = window;
        best_begin = begin;
        best_end = end;
      }
    }
    if (best < params_.parallel_support) return false;
    double weight_sum = 0.0, weighted_d = 0.0;
    for (size_t i = best_begin; i < best_end; ++i)
    {
      if (used_[i]) continue;
      weight_sum += frame_.blocks[offsets_[i].second].fit_weight;
      weighted_d += frame_.blocks[offsets_[i].second].fit_weight * offsets_[i].first;
    }
    d = modeNear(weighted_d / weight_sum);
    for (size_t i = best_begin; i < best_end; ++i) used_[i] = 1;
    return true;
  }

  // The interval may hold the tail of a neighbouring surface (a riser's top blocks below a
  // tread): shift to the mode, the mean of what lies within half the interval of it.
  double modeNear(double d) const
  {
    const double half = 0.5 * params_.support_distance;
    for (int step = 0; step < 5; ++step)
    {
      double shift_weight = 0.0, shifted = 0.0;
      for (auto it = std::lower_bound(offsets_.begin(), offsets_.end(), std::make_pair(d - half, -1));
           it != offsets_.end() && it->first <= d + half; ++it)
      {
        if (used_[it - offsets_.begin()]) continue;
        shift_weight += frame_.blocks[it->second].fit_weight;
        shifted += frame_.blocks[it->second].fit_weight * it->first;
      }
      if (shift_weight <= 0.0 || std::abs(shifted / shift_weight - d) < 1e-4) break;
      d = shifted / shift_weight;
    }
    return d;
  }

  bool sameAsCluster(const KnownPlane& plane, double d) const
  {
    const double sign = plane.normal.dot(normal_) >= 0.0 ? 1.0 : -1.0;
    return unsignedAngle(plane.normal, normal_) < params_.merge_angle &&
           std::abs(d - sign * plane.d) < 2.0 * params_.merge_distance;
  }

  // A cluster on a plane of this frame repeats it; one on a map plane measures it again
  // (else a plane only this search sees would never be voted for twice).
  bool repeatsAFramePlane(double d) const
  {
    for (const KnownPlane& plane : known_)
      if (!plane.in_map && sameAsCluster(plane, d)) return true;
    return false;
  }

  // Free blocks within their own noise of the cluster's plane; blocks that lie on a known
  // plane of another tilt (a floor beside a ramp) stay its own. Lying on it takes being thin
  // along its normal too: a stair riser's blocks are within reach of the tread planes above
  // and below it (and of a region across the steps) by their centroids, but spread over their
  // height along those normals.
  void clusterBlocks(double d, std::vector<int>& blocks) const
  {
    blocks.clear();
    // Offsets are sorted: only those within support_distance of d can be within reach.
    const auto first = std::lower_bound(offsets_.begin(), offsets_.end(), std::make_pair(d - params_.support_distance, -1));
    for (auto it = first; it != offsets_.end() && it->first <= d + params_.support_distance; ++it)
    {
      const BlockInfo& info = frame_.blocks[it->second];
      const double reach = std::min(params_.support_distance, info.tight_residual);
      if (frame_.block_claim[it->second] || std::abs(it->first - d) > reach) continue;
      bool on_known = false;
      for (const KnownPlane& plane : known_)
        if (!sameAsCluster(plane, d) && std::abs(plane.normal_cam.dot(info.centroid) + plane.d_cam) <= reach &&
            tests_.isThinAlong(it->second, plane.normal_cam))
          on_known = true;
      if (!on_known) blocks.push_back(it->second);
    }
  }

  void testCluster(double d)
  {
    const double d_cam = d + shift_;
    clusterBlocks(d, blocks_);
    // Patches must not be curved (a pillar's front is flat along a wall's normal for a hand's
    // width); a strip one block wide (a pillar's tangent line) shows no curvature across it,
    // and each patch must lie on the plane within its noise on its own, as others may be clutter.
    const PointMoments moments =
        tests_.keepFlatComponents(blocks_, params_.support_angle, 2, [&](const std::vector<int>& patch) {
          return tests_.centroidChi2(n_cam_, d_cam, patch) <= kMaxMeanCentroidChi2;
        });
    PlaneCandidate candidate{normal_, d, 0.0, moments.count, CandidateVerdict::kAccepted, true};
    // Together the patches lie on the plane within their noise (p = 0.01, as a grown region's
    // FramePlane::mixes_surfaces): a tangent strip's flanks and rows of other surfaces fail.
    if (!blocks_.empty() && tests_.centroidChi2(n_cam_, d_cam, blocks_) > noiseBoundOfMeanChi2(blocks_.size()))
      candidate.verdict = CandidateVerdict::kCentroidsOffPlane;
    else if (moments.count < params_.parallel_support)
      candidate.verdict = CandidateVerdict::kCurvedPatches;
    else if (!tests_.fitIsParallel(n_cam_, blocks_) ||
             !tests_.acceptsKnownNormal(tests_.explainNormal(n_cam_, blocks_, false), normal_))
      candidate.verdict = CandidateVerdict::kNotParallel;
    if (candidate.verdict == CandidateVerdict::kAccepted)
    {
      double weight_sum = 0.0, weighted_d = 0.0;
      for (int b : blocks_)
      {
        frame_.block_claim[b] = 1;
        weight_sum += frame_.blocks[b].fit_weight;
        weighted_d += frame_.blocks[b].fit_weight * (-n_cam_.dot(frame_.blocks[b].centroid) - shift_);
      }
      candidate.d = weighted_d / weight_sum;
      FramePlane plane;
      plane.normal = normal_;
      plane.d = candidate.d;
      plane.hough = param_.toHough(normal_, candidate.d);
      plane.support = moments.count;
      plane.parallel = true;
      plane.first_sight_points = tests_.firstSightPoints(blocks_);
      planes_.push_back(plane);
      addKnown(normal_, candidate.d, false);
    }
    candidates_.push_back(candidate);
  }

  const DetectorParams& params_;
  const HoughParameterization& param_;
  FrameData& frame_;
  const PlanarityTests& tests_;
  std::vector<FramePlane>& planes_;
  std::vector<PlaneCandidate>& candidates_;
  std::vector<KnownPlane> known_;  // in both frames
  Eigen::Vector3d normal_, n_cam_;  // the direction searched
  double shift_ = 0.0;
  std::vector<std::pair<double, int>> offsets_;  // world d of each flat free block, sorted
  std::vector<char> used_;
  std::vector<double> offset_points_;  // points of each entry of offsets_, read once
  std::vector<int> blocks_;
};
}  // namespace

void findParallelPlanes(const DetectorParams& params, const HoughParameterization& param, FrameData& frame,
                        const PlanarityTests& tests, const std::vector<DetectedPlane>& map_planes,
                        std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates)
{
  if (params.parallel_support <= 0) return;
  ParallelSearch search(params, param, frame, tests, planes, candidates);
  for (const FramePlane& plane : planes) search.addKnown(plane.normal, plane.d, false);
  for (const DetectedPlane& plane : map_planes) search.addKnown(plane.normal, plane.d, true);
  for (const Eigen::Vector3d& direction : search.directions()) search.searchAlong(direction);
}

}  // namespace hough_plane_detector
