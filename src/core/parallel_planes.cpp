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
}  // namespace

void findParallelPlanes(const DetectorParams& params, const HoughParameterization& param, FrameData& frame,
                        const PlanarityTests& tests, const std::vector<DetectedPlane>& map_planes,
                        std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates)
{
  if (params.parallel_support <= 0) return;
  std::vector<Eigen::Vector3d> directions;
  struct KnownPlane
  {
    Eigen::Vector3d normal, normal_cam;
    double d, d_cam;
    bool in_map;  // a map plane not yet seen in this frame: a cluster on it confirms it
  };
  std::vector<KnownPlane> known;  // in both frames
  auto addKnown = [&](const Eigen::Vector3d& normal, double d, bool in_map) {
    known.push_back({normal, frame.camera_to_world.linear().transpose() * normal, d,
                     d + normal.dot(frame.camera_to_world.translation()), in_map});
  };
  for (const FramePlane& plane : planes) addKnown(plane.normal, plane.d, false);
  for (const DetectedPlane& plane : map_planes) addKnown(plane.normal, plane.d, true);
  for (const KnownPlane& plane : known)
  {
    bool seen = false;
    for (const Eigen::Vector3d& direction : directions) seen |= unsignedAngle(direction, plane.normal) < params.merge_angle;
    if (!seen) directions.push_back(plane.normal);
  }

  const int count = static_cast<int>(frame.blocks.size());
  const int bx_count = frame.normals.blocksX();
  std::vector<std::pair<double, int>> offsets;  // world d of each flat free block, sorted
  std::vector<char> used;
  std::vector<int> blocks;
  for (const Eigen::Vector3d& normal : directions)
  {
    const Eigen::Vector3d n_cam = frame.camera_to_world.linear().transpose() * normal;
    const double shift = normal.dot(frame.camera_to_world.translation());  // d_world = d_cam - shift
    offsets.clear();
    for (int b = 0; b < count; ++b)
    {
      const BlockInfo& info = frame.blocks[b];
      if (!info.valid || frame.block_claim[b] || n_cam.dot(info.covariance * n_cam) > info.thickness_limit) continue;
      // A block says which side of its neighbours it lies on only if its centroid is much more
      // precise than the cluster width; and seen along the plane (grazing rays), a wall's block
      // is as thin along the normal as a floor's: there the thickness test means nothing.
      if (info.centroid_variance > kMaxParallelCentroidSigma * kMaxParallelCentroidSigma * params.support_distance *
                                       params.support_distance ||
          std::abs(n_cam.dot(info.centroid.normalized())) < kMinParallelGrazingSine)
        continue;
      offsets.emplace_back(-n_cam.dot(info.centroid) - shift, b);
    }
    std::sort(offsets.begin(), offsets.end());
    used.assign(offsets.size(), 0);
    auto points = [&](size_t i) { return used[i] ? 0.0 : frame.normals.block(offsets[i].second % bx_count, offsets[i].second / bx_count).count; };
    while (true)
    {
      // The densest interval of support_distance in d, by points.
      double best = 0.0, window = 0.0;
      size_t best_begin = 0, best_end = 0;
      for (size_t begin = 0, end = 0; begin < offsets.size(); window -= points(begin), ++begin)
      {
        for (; end < offsets.size() && offsets[end].first <= offsets[begin].first + params.support_distance; ++end)
          window += points(end);
        if (window > best)
        {
          best = window;
          best_begin = begin;
          best_end = end;
        }
      }
      if (best < params.parallel_support) break;
      double weight_sum = 0.0, weighted_d = 0.0;
      for (size_t i = best_begin; i < best_end; ++i)
      {
        if (used[i]) continue;
        weight_sum += frame.blocks[offsets[i].second].fit_weight;
        weighted_d += frame.blocks[offsets[i].second].fit_weight * offsets[i].first;
      }
      double d = weighted_d / weight_sum;
      // The interval may hold the tail of a neighbouring surface (a riser's top blocks below a
      // tread): shift to the mode, the mean of what lies within half the interval of it.
      for (int step = 0; step < 5; ++step)
      {
        const double half = 0.5 * params.support_distance;
        double shift_weight = 0.0, shifted = 0.0;
        for (auto it = std::lower_bound(offsets.begin(), offsets.end(), std::make_pair(d - half, -1));
             it != offsets.end() && it->first <= d + half; ++it)
        {
          if (used[it - offsets.begin()]) continue;
          shift_weight += frame.blocks[it->second].fit_weight;
          shifted += frame.blocks[it->second].fit_weight * it->first;
        }
        if (shift_weight <= 0.0 || std::abs(shifted / shift_weight - d) < 1e-4) break;
        d = shifted / shift_weight;
      }
      for (size_t i = best_begin; i < best_end; ++i) used[i] = 1;
      // A cluster on a plane of this frame repeats it; one on a map plane measures it again
      // (else a plane only this search sees would never be voted for twice).
      auto sameAsCluster = [&](const KnownPlane& plane) {
        const double sign = plane.normal.dot(normal) >= 0.0 ? 1.0 : -1.0;
        return unsignedAngle(plane.normal, normal) < params.merge_angle &&
               std::abs(d - sign * plane.d) < 2.0 * params.merge_distance;
      };
      bool repeats = false;
      for (const KnownPlane& plane : known) repeats |= !plane.in_map && sameAsCluster(plane);
      // Surfaces cut by a plane through the sensor all project to one image line, whose blocks
      // form that plane for any surface behind them: no plane can be seen edge-on.
      const double d_cam = d + shift;
      if (repeats || std::abs(d_cam) < 2.0 * params.support_distance) continue;
      // Its blocks: free ones within their own noise of the cluster's plane, in patches that
      // are not curved (a pillar's front is flat along a wall's normal for a hand's width).
      // Blocks that lie on a known plane of another tilt (a floor beside a ramp) stay its own.
      blocks.clear();
      // Offsets are sorted: only those within support_distance of d can be within reach.
      const auto first = std::lower_bound(offsets.begin(), offsets.end(), std::make_pair(d - params.support_distance, -1));
      for (auto it = first; it != offsets.end() && it->first <= d + params.support_distance; ++it)
      {
        const auto& offset = *it;
        const BlockInfo& info = frame.blocks[offset.second];
        const double reach = std::min(params.support_distance, info.tight_residual);
        if (frame.block_claim[offset.second] || std::abs(offset.first - d) > reach) continue;
        bool on_known = false;
        for (const KnownPlane& plane : known)
          if (!sameAsCluster(plane) && std::abs(plane.normal_cam.dot(info.centroid) + plane.d_cam) <= reach)
            on_known = true;
        if (!on_known) blocks.push_back(offset.second);
      }
      // A strip one block wide (a pillar's tangent line) shows no curvature across it; each
      // patch must lie on the plane within its noise on its own, as others may be clutter.
      const PointMoments moments = tests.keepFlatComponents(blocks, params.support_angle, 2, [&](const std::vector<int>& patch) {
        return tests.centroidChi2(n_cam, d_cam, patch) <= kMaxMeanCentroidChi2;
      });
      PlaneCandidate candidate{normal, d, 0.0, moments.count, CandidateVerdict::kAccepted, true};
      if (moments.count < params.parallel_support)
        candidate.verdict = CandidateVerdict::kCurvedPatches;
      else if (!tests.fitIsParallel(n_cam, blocks) || !tests.explainedByNormal(n_cam, blocks))
        candidate.verdict = CandidateVerdict::kNotParallel;
      if (candidate.verdict == CandidateVerdict::kAccepted)
      {
        weight_sum = weighted_d = 0.0;
        for (int b : blocks)
        {
          frame.block_claim[b] = 1;
          weight_sum += frame.blocks[b].fit_weight;
          weighted_d += frame.blocks[b].fit_weight * (-n_cam.dot(frame.blocks[b].centroid) - shift);
        }
        d = candidate.d = weighted_d / weight_sum;
        FramePlane peak;
        peak.normal = normal;
        peak.d = d;
        peak.hough = param.toHough(normal, d);
        peak.value = 0.0;
        peak.support = moments.count;
        peak.parallel = true;
        planes.push_back(peak);
        addKnown(normal, d, false);
      }
      candidates.push_back(candidate);
    }
  }
}

}  // namespace hough_plane_detector
