#include "hough_plane_detector/core/plane_map.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include <Eigen/Eigenvalues>
#include <boost/math/distributions/chi_squared.hpp>

#include "hough_plane_detector/core/block_regions.h"
#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{
namespace
{
// Beyond the merge tolerances, where a noisy re-measurement of a plane still falls.
constexpr double kNearTolerances = 3.0;
// Pooled snapped tilts that refute a map plane's normal: chi^2 with 2 dof, p = 0.001.
constexpr double kRefutedSnapChi2 = 13.82;
// Camera displacement over the distance to a face below which two frames share a viewpoint.
constexpr double kSameViewpoint = 8.0 / 580.0;
// How far off one surface's measurements may pass each other's points: three sigmas of their
// offsets' noise (the summed variance) and a face's warp.
double surfaceReach(double offset_variance)
{
  return 3.0 * std::sqrt(offset_variance + kSurfaceWarp * kSurfaceWarp);
}
// A snapped measurement's own normal as a tilt across `direction` (the normal it took), and
// that tilt's information (1/rad^2), both in the plane across `direction`.
struct SnapTilt
{
  Eigen::Vector3d tilt;
  Eigen::Matrix3d information;
};
SnapTilt snapTilt(const FramePlane& measured, const Eigen::Vector3d& direction)
{
  const Eigen::Vector3d own = direction.dot(measured.own_normal) >= 0.0 ? measured.own_normal : -measured.own_normal;
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - direction * direction.transpose();
  return {across * own, across * measured.own_normal_information * across};
}
}  // namespace

PlaneMap::PlaneMap(const DetectorParams& params, const HoughParameterization& param, const HoughVoting& voting,
                   const HoughPeakSearch& peak_search)
  : params_(params)
  , param_(param)
  , voting_(voting)
  , peak_search_(peak_search)
  , global_(param.sizeAngle(), param.sizeAngle(), param.sizeD())
{
}

void PlaneMap::clear()
{
  chunks_evicted_total_ = 0;
  extents_.clear();
  beliefs_.clear();
  snap_tilts_.clear();
  frame_count_ = 0;
  global_.clear();
  planes_.clear();
  first_sights_.clear();
  next_id_ = 0;
}

void PlaneMap::checkEvidence(const CloudView& cloud, const Eigen::Isometry3d& camera_to_world,
                             const PinholeIntrinsics& intrinsics, const DepthNoiseModel& noise)
{
  for (const DetectedPlane& plane : planes_)
  {
    const auto extent = extents_.find(plane.id);
    if (extent == extents_.end()) continue;
    const PlaneEvidence evidence = checkPlaneEvidence(extent->second, plane.normal, plane.d, cloud, camera_to_world,
                                                      intrinsics, noise, frame_count_, extentFade());
    beliefs_[plane.id].update(evidence);
  }
}

int PlaneMap::accumulate(const std::vector<FramePlane>& frame_planes, const Eigen::Vector3d& camera_position,
                         double stamp)
{
  const float cap = static_cast<float>(params_.permanence_cap);
  // Thinning first, so a plane seen in this frame ends the frame at least 1 higher.
  thin(cap, frame_planes);
  const std::vector<char> dropped = dropSuperseded(frame_planes);
  // Algorithm 2: every frame plane adds one Gaussian; the peaks are seeded from the cells of
  // this frame's planes and of the map's.
  // A plane this frame measured strongly enough to be reported at first sight (weight 2) is
  // judged by its peak's height, not by its nearest cell, which reads 1.37-2 by where it fell.
  std::vector<Eigen::Vector3i> seeds;
  std::vector<char> full_height;
  first_sights_.resize(frame_planes.size());
  for (size_t i = 0; i < frame_planes.size(); ++i)
  {
    const FramePlane& plane = frame_planes[i];
    const float weight = voteWeight(plane, frame_planes, dropped, first_sights_[i]);
    full_height.push_back(weight >= 2.0f);
    addVote(plane.hough, weight, cap);
    seeds.push_back(nearestCell(param_.toCell(plane.hough)));
  }
  for (const DetectedPlane& plane : planes_) seeds.push_back(nearestCell(param_.toCell(plane.hough)));
  const int evicted = static_cast<int>(global_.evictWeakest(static_cast<size_t>(params_.max_chunks)));
  chunks_evicted_total_ += evicted;

  std::vector<Eigen::Vector3i> seed_tops;
  std::vector<HoughPeak> extracted =
      peak_search_.extract(global_, seeds, params_.global_threshold, full_height, &seed_tops);
  addCloseSurfacePeaks(frame_planes, seed_tops, extracted);
  const std::vector<HoughPeak> peaks =
      mergeSimilarPeaks(std::move(extracted),
                        params_.merge_angle, params_.merge_distance, param_,
                        [&](const HoughPeak& a, const HoughPeak& b) { return measuredApart(a, b, frame_planes); });
  matchIds(peaks, camera_position, stamp);
  if (params_.forgetting == kForgetByEvidence)
  {
    carryBeliefs();
    countOneSurfaceMeasurements(frame_planes);
  }
  reseatRefutedSnaps(frame_planes, camera_position);
  return evicted;
}

void PlaneMap::addCloseSurfacePeaks(const std::vector<FramePlane>& frame_planes,
                                    const std::vector<Eigen::Vector3i>& seed_tops, std::vector<HoughPeak>& peaks) const
{
  // The grid cannot resolve two parallel surfaces a cell or two apart (two table tops 1.5 cm
  // apart): their votes climb to one maximum, whose mean lies between them. When this frame
  // measured them apart beyond their noise, or the map held them apart, each surface gets a
  // peak of its own at its own place: as this frame measured it, else as the map held it.
  // The extraction's climbs from each frame plane's and map plane's cell (the seeds).
  const auto frame_tops = seed_tops.begin();
  const auto map_tops = seed_tops.begin() + static_cast<std::ptrdiff_t>(frame_planes.size());
  const size_t extracted = peaks.size();
  for (size_t k = 0; k < extracted; ++k)
  {
    const Eigen::Vector3i top = peak_search_.climb(global_, nearestCell(param_.toCell(peaks[k].hough)));
    // This frame's surfaces on the peak: the plane nearest it, then, best supported first, each
    // one precise enough to be reported at first sight and apart from those already taken.
    std::vector<const FramePlane*> measured;
    for (size_t i = 0; i < frame_planes.size(); ++i)
      if (frame_tops[i] == top) measured.push_back(&frame_planes[i]);
    std::stable_sort(measured.begin(), measured.end(),
                     [](const FramePlane* a, const FramePlane* b) { return a->support > b->support; });
    const auto nearest =
        std::min_element(measured.begin(), measured.end(), [&](const FramePlane* a, const FramePlane* b) {
          return mergeCost(*a, peaks[k]) < mergeCost(*b, peaks[k]);
        });
    if (nearest != measured.end()) std::rotate(measured.begin(), nearest, std::next(nearest));
    // Two surfaces that share a maximum are parallel within their normals' noise (a box top
    // beside a table top, both snapped to the floor's normal); a region tilted beyond it and
    // offset too is one surface's biased fit (a far stretch of floor), not a second surface.
    auto parallel = [](const FramePlane& a, const FramePlane& b) {
      return unsignedAngle(a.normal, b.normal) <=
             3.0 * std::sqrt(a.normal_sigma * a.normal_sigma + b.normal_sigma * b.normal_sigma);
    };
    // Both sides of a split are measurements a first sight would report: one that does not fit
    // its blocks, or is imprecise, says nothing about a second surface beside it.
    auto trusted = [&](const FramePlane& p) { return p.fits_its_blocks && preciseAtFirstSight(p); };
    std::vector<const FramePlane*> surfaces;
    for (const FramePlane* plane : measured)
      if (surfaces.empty() ||
          (trusted(*surfaces.front()) && trusted(*plane) &&
           std::all_of(surfaces.begin(), surfaces.end(), [&](const FramePlane* s) {
             return distinctSurfaces(*plane, *s) && parallel(*plane, *s);
           })))
        surfaces.push_back(plane);
    // The map's planes on the peak that no surface of this frame re-measured (none is nearer it
    // than to the others of the map): the one nearest the peak, and those held apart that later
    // frames' depths confirmed (not tentative).
    std::vector<const DetectedPlane*> on_peak;
    for (size_t i = 0; i < planes_.size(); ++i)
      if (map_tops[i] == top) on_peak.push_back(&planes_[i]);
    const DetectedPlane* map_nearest = nullptr;
    for (const DetectedPlane* plane : on_peak)
      if (!map_nearest || mergeCost(*plane, peaks[k]) < mergeCost(*map_nearest, peaks[k])) map_nearest = plane;
    std::vector<const DetectedPlane*> held;
    for (const DetectedPlane* plane : on_peak)
    {
      const bool remeasured = std::any_of(surfaces.begin(), surfaces.end(), [&](const FramePlane* s) {
        return std::none_of(on_peak.begin(), on_peak.end(),
                            [&](const DetectedPlane* o) { return mergeCost(*o, *s) < mergeCost(*plane, *s); });
      });
      if (remeasured) continue;
      const auto belief = beliefs_.find(plane->id);
      const bool confirmed = belief != beliefs_.end() && !belief->second.tentative() && !belief->second.gone();
      if ((surfaces.empty() && plane == map_nearest) || confirmed) held.push_back(plane);
    }
    std::vector<Eigen::Vector3d> places;
    for (const FramePlane* plane : surfaces) places.push_back(plane->hough);
    for (const DetectedPlane* plane : held) places.push_back(plane->hough);
    if (places.size() < 2) continue;
    // The first takes the maximum's height; each other stands on its own cell's.
    for (size_t i = 0; i < places.size(); ++i)
    {
      HoughPeak own = peaks[k];
      own.hough = places[i];
      param_.fromHough(own.hough, own.normal, own.d);
      if (i == 0)
      {
        peaks[k] = own;
        continue;
      }
      const Eigen::Vector3i c = nearestCell(param_.toCell(own.hough));
      own.value = global_.value(c.x(), c.y(), c.z());
      if (own.value >= params_.global_threshold) peaks.push_back(own);
    }
  }
}

void PlaneMap::reseatRefutedSnaps(const std::vector<FramePlane>& frame_planes, const Eigen::Vector3d& camera_position)
{
  // Records of planes that left the map go with them.
  for (auto it = snap_tilts_.begin(); it != snap_tilts_.end();)
  {
    const bool kept = std::any_of(planes_.begin(), planes_.end(), [&](const DetectedPlane& p) { return p.id == it->first; });
    it = kept ? std::next(it) : snap_tilts_.erase(it);
  }
  std::vector<char> updated(planes_.size(), 0);
  for (const FramePlane& measured : frame_planes)
  {
    if (measured.own_normal.isZero()) continue;
    const int match = remeasuredPlane(measured);
    if (match < 0) continue;
    const SnapTilt own = snapTilt(measured, planes_[match].normal);
    SnapTilts& tilts = snap_tilts_[planes_[match].id];
    // A new viewpoint when the camera moved a block's width as seen from the face (8 of a
    // Kinect's 580 px): the depth errors fixed to pixels then fall elsewhere on it.
    const bool same_viewpoint = tilts.viewpoint_frames > 0 && (camera_position - tilts.viewpoint).norm() <
                                                                  kSameViewpoint * (measured.centroid - camera_position).norm();
    if (!same_viewpoint)
    {
      if (tilts.viewpoint_frames > 0)
      {
        tilts.information += tilts.viewpoint_information / tilts.viewpoint_frames;
        tilts.weighted_tilt += tilts.viewpoint_weighted_tilt / tilts.viewpoint_frames;
      }
      tilts.viewpoint_information.setZero();
      tilts.viewpoint_weighted_tilt.setZero();
      tilts.viewpoint_frames = 0;
      tilts.viewpoint = camera_position;
    }
    if (tilts.last_frame != frame_count_) ++tilts.viewpoint_frames;
    tilts.last_frame = frame_count_;
    tilts.viewpoint_information += own.information;
    tilts.viewpoint_weighted_tilt += own.information * own.tilt;
    tilts.centroid_sum += measured.centroid;
    ++tilts.measurements;
    updated[match] = 1;
  }
  const float cap = static_cast<float>(params_.permanence_cap);
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    if (!updated[p]) continue;
    DetectedPlane& plane = planes_[p];
    const SnapTilts& tilts = snap_tilts_[plane.id];
    const Eigen::Matrix3d pooled = tilts.information + tilts.viewpoint_information / tilts.viewpoint_frames;
    const Eigen::Vector3d weighted_tilt = tilts.weighted_tilt + tilts.viewpoint_weighted_tilt / tilts.viewpoint_frames;
    // The pooled tilt lies across the normal; the normal's own direction is made invertible.
    const Eigen::Matrix3d information = pooled + (pooled.trace() + 1e-12) * plane.normal * plane.normal.transpose();
    const Eigen::Vector3d tilt = information.ldlt().solve(weighted_tilt);
    if (!(weighted_tilt.dot(tilt) > kRefutedSnapChi2)) continue;  // also when not finite
    const Eigen::Vector3d normal = (plane.normal + tilt).normalized();
    const double d = -normal.dot(tilts.centroid_sum / tilts.measurements);
    clearOwnPeakCells(p);
    plane.normal = normal;
    plane.d = d;
    plane.hough = param_.toHough(normal, d);
    addVote(plane.hough, std::min(static_cast<float>(plane.strength), cap), cap);
    snap_tilts_.erase(plane.id);
  }
}

double PlaneMap::mergeCost(const Eigen::Vector3d& normal_a, double d_a, const Eigen::Vector3d& normal_b,
                           double d_b) const
{
  const double sign = normal_a.dot(normal_b) >= 0.0 ? 1.0 : -1.0;
  return unsignedAngle(normal_a, normal_b) / params_.merge_angle + std::abs(sign * d_a - d_b) / params_.merge_distance;
}

void PlaneMap::addVote(const Eigen::Vector3d& hough, float weight, float cap)
{
  voting_.addGaussian(global_, hough, weight, cap);
  Eigen::Vector3d mirrored;
  if (param_.mirror(hough, mirrored)) voting_.addGaussian(global_, mirrored, weight, cap);
}

void PlaneMap::clearOwnPeakCells(size_t index)
{
  forOwnPeakCells(index, [&](int x, int y, int z) {
    const float v = global_.value(x, y, z);
    if (v > 0.0f) global_.add(x, y, z, -v);
  });
}

void PlaneMap::forOwnPeakCells(size_t index, const std::function<void(int, int, int)>& f) const
{
  // Cells nearer another map plane's peak are that plane's votes, however close the two lie.
  std::vector<Eigen::Vector3d> own{param_.toCell(planes_[index].hough)};
  Eigen::Vector3d mirrored;
  if (param_.mirror(planes_[index].hough, mirrored)) own.push_back(param_.toCell(mirrored));
  // A visited cell lies within sqrt(3) (r + 1/2) of an own centre (r: forPeakCells' reach, plus
  // the rounding of the centre), so only a peak within twice that can be nearer to it.
  const double reach = 2.0 * std::sqrt(3.0) * (voting_.blurRadius() + params_.peak_window / 2 + 1.5);
  std::vector<Eigen::Vector3d> others;
  auto consider = [&](const Eigen::Vector3d& hough) {
    const Eigen::Vector3d c = param_.toCell(hough);
    for (const Eigen::Vector3d& o : own)
      if ((c - o).squaredNorm() <= reach * reach)
      {
        others.push_back(c);
        return;
      }
  };
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    if (p == index) continue;
    consider(planes_[p].hough);
    Eigen::Vector3d other_mirrored;
    if (param_.mirror(planes_[p].hough, other_mirrored)) consider(other_mirrored);
  }
  forPeakCells(planes_[index].hough, [&](int x, int y, int z) {
    const Eigen::Vector3d cell(x, y, z);
    double nearest_own = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& c : own) nearest_own = std::min(nearest_own, (cell - c).squaredNorm());
    for (const Eigen::Vector3d& c : others)
      if ((cell - c).squaredNorm() < nearest_own) return;
    f(x, y, z);
  });
}

bool PlaneMap::measuredApart(const HoughPeak& a, const HoughPeak& b, const std::vector<FramePlane>& frame_planes) const
{
  // Two nearby peaks are two surfaces when one frame measured a plane at each (two box tops a
  // few cm apart), or the map already held them apart; else they are one plane's measurements.
  // Planes of one list, one nearer each peak, that are two surfaces themselves.
  auto apart = [&](const auto& planes, const auto& two_surfaces) {
    for (const auto& near_a : planes)
    {
      const double a_to_a = mergeCost(near_a, a);
      if (a_to_a > 1.0 || a_to_a >= mergeCost(near_a, b)) continue;
      for (const auto& near_b : planes)
      {
        const double b_to_b = mergeCost(near_b, b);
        if (b_to_b > 1.0 || b_to_b >= mergeCost(near_b, a)) continue;
        if (two_surfaces(near_a, near_b)) return true;
      }
    }
    return false;
  };
  return apart(frame_planes, [&](const FramePlane& x, const FramePlane& y) { return distinctSurfaces(x, y); }) ||
         apart(planes_, [](const DetectedPlane&, const DetectedPlane&) { return true; });
}

bool PlaneMap::distinctSurfaces(const FramePlane& a, const FramePlane& b) const
{
  if (!withinMergeTolerances(a.normal, a.d, b.normal, b.d, params_.merge_angle, params_.merge_distance)) return true;
  if (!(a.offset_sigma > 0.0 && b.offset_sigma > 0.0)) return false;
  // Measured in one frame, no pose error lies between them: one surface's two regions differ
  // by their offsets' noise, the face's warp, and their normals' difference over the distance.
  const double sign = a.normal.dot(b.normal) >= 0.0 ? 1.0 : -1.0;
  const Eigen::Vector3d between = b.centroid - a.centroid;
  const double gap = std::abs((a.normal + sign * b.normal).normalized().dot(between));
  const double allowed = surfaceReach(a.offset_sigma * a.offset_sigma + b.offset_sigma * b.offset_sigma) +
                         unsignedAngle(a.normal, b.normal) * between.norm();
  return gap > allowed;
}

void PlaneMap::thin(float cap, const std::vector<FramePlane>& frame_planes)
{
  // By evidence, what is out of view keeps its state; the rest thins as in the paper.
  if (params_.forgetting == kForgetByEvidence)
    thinByEvidence(cap, frame_planes);
  else
    global_.thin(static_cast<float>(params_.thinning_rate), cap);
}

float PlaneMap::voteWeight(const FramePlane& plane, const std::vector<FramePlane>& frame_planes,
                           const std::vector<char>& dropped, FirstSight& first_sight) const
{
  // A plane not yet in the map adds up to 2 when strongly supported, so that a big plane is
  // reported the first time it is seen, while known planes gain 1 per frame as in the paper
  // (thinning and permanence keep their pace). Noisier sensors need more points for the same
  // precision: the bar rises with sensor_noise^2, and near points count more (detector_params.h).
  // A plane of the parallel search, or one snapped to a known normal, measured only its
  // offset, so a quarter of the points is as strong; not so a grown region that does not fit
  // its blocks (FramePlane::fits_its_blocks): it mixes surfaces (a shelf board's top with its
  // front), and its offset is none of theirs. One of under 2 min_support points is too
  // small for the curvature tests: it waits for a second frame, unless it is parallel and its
  // weighted points reach the full bar (a box top near the sensor).
  first_sight = FirstSight::kKnownPlane;
  for (const DetectedPlane& known : planes_)
    if (samePlane(known, plane)) return 1.0f;
  first_sight = FirstSight::kTooSmall;  // every new plane is, with first-sight reports off
  if (params_.strong_support <= 0) return 1.0f;
  // A region whose blocks lie off its plane beyond their noise is no measurement of one
  // surface, however large: it does not vote. A second frame from nearly the same view grows
  // the same mixture (stair treads with the ramp beside them), so repeating it proves nothing.
  if (plane.mixes_surfaces)
  {
    first_sight = FirstSight::kMixesSurfaces;
    return 0.0f;
  }
  const double strong_support = params_.strong_support * std::max(1.0, params_.sensor_noise * params_.sensor_noise);
  // Whether a surface is too small for the curvature tests does not depend on how many regions
  // the frame grew on it (a box top split in two): that test pools the points and support of
  // this frame's planes the merge would join. The weight is each measurement's own.
  double points = plane.first_sight_points, support = plane.support;
  for (const FramePlane& other : frame_planes)
  {
    if (&other != &plane && withinMergeTolerances(plane.normal, plane.d, other.normal, other.d, params_.merge_angle,
                                                  params_.merge_distance))
    {
      points += other.first_sight_points;
      support += other.support;
    }
  }
  if (support < 2.0 * params_.min_support && !(plane.parallel && points >= strong_support)) return 1.0f;
  // A region whose blocks pass the noise tests of a plane (FramePlane::fits_its_blocks, or
  // level_strip's offset test) is a complete measurement of a new surface whatever its size:
  // one frame reports it, when it is precise enough that a second measurement would agree
  // with it. Near a known plane it may be that plane measured badly, and waits for a second
  // frame; not near one this frame's measurements just replaced.
  const bool fits = plane.fits_its_blocks || plane.level_strip;
  if (!fits && partOfMeasuredSurface(plane, frame_planes))
    first_sight = FirstSight::kPartOfMeasuredSurface;
  else if (!fits)
    first_sight = plane.blocks.empty() ? FirstSight::kWithoutBlocks : FirstSight::kNotFittingItsBlocks;
  else if (!preciseAtFirstSight(plane, frame_planes))
    first_sight = FirstSight::kImprecise;
  else
    first_sight = nearKnownPlane(plane, dropped) ? FirstSight::kNearKnownPlane : FirstSight::kComplete;
  if (first_sight == FirstSight::kPartOfMeasuredSurface) return 0.0f;
  if (first_sight == FirstSight::kComplete) return 2.0f;
  const bool offset_only = plane.parallel && (plane.blocks.empty() || fits);
  const double bar = offset_only ? 0.25 * strong_support : strong_support;
  return static_cast<float>(1.0 + std::min(1.0, plane.first_sight_points / bar));
}

const char* toString(FirstSight first_sight)
{
  switch (first_sight)
  {
    case FirstSight::kKnownPlane:
      return "a map plane's";
    case FirstSight::kMixesSurfaces:
      return "mixes surfaces";
    case FirstSight::kPartOfMeasuredSurface:
      return "part of a surface the frame measured";
    case FirstSight::kTooSmall:
      return "too small to report at first sight";
    case FirstSight::kComplete:
      return "complete at first sight";
    case FirstSight::kWithoutBlocks:
      return "measured without blocks (parallel search or windows)";
    case FirstSight::kNotFittingItsBlocks:
      return "does not fit its blocks";
    case FirstSight::kImprecise:
      return "imprecise at first sight";
    case FirstSight::kNearKnownPlane:
      return "near a map plane";
  }
  return "unknown";
}

namespace
{
// Two measurements of one surface differ by sqrt(2) sigma; a tolerance holds at 2 sigma of that
// difference.
constexpr double kFirstSightSigmas = 2.0 * M_SQRT2;

// The offset is judged where the surface was measured, at its points: a far face's small tilt
// error moves its offset at the world origin, not the surface shown.
bool offsetPreciseAtFirstSight(const FramePlane& measured, double merge_distance)
{
  return kFirstSightSigmas * measured.offset_sigma <= merge_distance;
}
}  // namespace

bool PlaneMap::preciseAtFirstSight(const FramePlane& measured) const
{
  const bool offset_precise = offsetPreciseAtFirstSight(measured, params_.merge_distance);
  // A level snap's normal is gravity's, as precise as the map's level planes.
  if (measured.level_snap) return offset_precise;
  return offset_precise && kFirstSightSigmas * measured.normal_sigma <= params_.merge_angle;
}

bool PlaneMap::preciseAtFirstSight(const FramePlane& measured, const std::vector<FramePlane>& frame_planes) const
{
  if (preciseAtFirstSight(measured)) return true;
  return offsetPreciseAtFirstSight(measured, params_.merge_distance) &&
         kFirstSightSigmas * sharedDirectionSigma(measured, frame_planes) <= params_.merge_angle;
}

bool PlaneMap::partOfMeasuredSurface(const FramePlane& region, const std::vector<FramePlane>& frame_planes) const
{
  // Two surfaces meet only along their edges, so a face of its own lies off another's plane by
  // half its extent times the sine of their angle. A region centred on a surface this frame
  // measured, whose blocks do not fit one plane, is that surface bent where the sensor bends
  // it (a table's image corner 0.6 m from a structured-light camera, 0.1-0.17 rad off and
  // 3-5 mm from the table at its centroid in osd-learn) or a part of it with a stray rim.
  // One within the merge tolerances votes for that surface's plane (a snapped rest of a face).
  if (region.blocks.empty()) return false;
  return std::any_of(frame_planes.begin(), frame_planes.end(), [&](const FramePlane& surface) {
    return &surface != &region && surface.fits_its_blocks && surface.support > region.support &&
           std::abs(surface.normal.dot(region.centroid) + surface.d) <= kSurfaceWarp &&
           unsignedAngle(surface.normal, region.normal) < kCreaseAngle &&
           !withinMergeTolerances(surface.normal, surface.d, region.normal, region.d, params_.merge_angle,
                                  params_.merge_distance);
  });
}

double PlaneMap::sharedDirectionSigma(const FramePlane& snapped, const std::vector<FramePlane>& frame_planes) const
{
  // Surfaces that took one known direction in one frame (the risers of a staircase) are
  // parallel if the snaps are right, so their own normals measure that one direction together:
  // each tilt t_i off it, with information I_i, pools to t = (sum I_i)^-1 sum I_i t_i. The
  // direction is confirmed when t is within the pooled noise (chi^2, 2 dof) and the tilts
  // scatter about t no more than their noise (chi^2, 2 (k - 1) dof). A map plane measured again
  // is no member: its precise normal would vouch for any face that snapped to it.
  constexpr double kSameDirection = 1e-4;  // rad: snapped planes carry the known normal exactly
  constexpr double kP = 0.01;
  const double infinite = std::numeric_limits<double>::infinity();
  if (!snapped.parallel || snapped.own_normal.isZero()) return infinite;
  const Eigen::Vector3d& direction = snapped.normal;
  const Eigen::Vector3d u = direction.unitOrthogonal();
  Eigen::Matrix<double, 3, 2> tangent;
  tangent << u, direction.cross(u);
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
  Eigen::Vector2d weighted_tilt = Eigen::Vector2d::Zero();
  double chi2_each = 0.0;
  int members = 0;
  for (const FramePlane& other : frame_planes)
  {
    if (!other.parallel || other.own_normal.isZero() || !other.fits_its_blocks ||
        unsignedAngle(other.normal, direction) > kSameDirection)
      continue;
    if (std::any_of(planes_.begin(), planes_.end(), [&](const DetectedPlane& known) { return samePlane(known, other); }))
      continue;
    const SnapTilt own = snapTilt(other, direction);
    const Eigen::Vector2d tilt = tangent.transpose() * own.tilt;
    const Eigen::Matrix2d own_information = tangent.transpose() * own.information * tangent;
    information += own_information;
    weighted_tilt += own_information * tilt;
    chi2_each += tilt.dot(own_information * tilt);
    ++members;
  }
  if (members < 2) return infinite;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(information);
  if (!(eigen.eigenvalues()(0) > 0.0)) return infinite;
  const Eigen::Vector2d pooled_tilt = information.ldlt().solve(weighted_tilt);
  const double chi2_pooled = pooled_tilt.dot(information * pooled_tilt);
  const boost::math::chi_squared scatter(2.0 * (members - 1));
  if (chi2_pooled > kMaxSnapChi2Increase ||
      chi2_each - chi2_pooled > boost::math::quantile(boost::math::complement(scatter, kP)))
    return infinite;
  return 1.0 / std::sqrt(eigen.eigenvalues()(0));
}

std::vector<char> PlaneMap::dropSuperseded(const std::vector<FramePlane>& frame_planes)
{
  // A young plane (peak at most 2: one first-sight vote or two plain ones) that this frame does
  // not measure again, while it measures a plane of at least its support near it (nearPlane:
  // within three merge tolerances at the measurement's points), was that surface measured
  // badly: the better measurement replaces it rather than stand beside it. Only its own cells
  // go: a neighbour's peak (a surface beside it) keeps its votes.
  std::vector<char> dropped(planes_.size(), 0);
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    const DetectedPlane& plane = planes_[p];
    if (plane.strength > 2.0 || remeasured(plane, frame_planes)) continue;
    for (const FramePlane& measured : frame_planes)
    {
      if (measured.support < plane.support || !nearPlane(plane, measured)) continue;
      clearOwnPeakCells(p);
      dropped[p] = 1;
      break;
    }
  }
  return dropped;
}

bool PlaneMap::nearKnownPlane(const FramePlane& measured, const std::vector<char>& dropped) const
{
  // A bad measurement of a known surface turns about its centroid, which stays on that surface:
  // a known plane that passes the centroid farther off than the measurement's offset noise and
  // a face's warp allow (3 sigma, as distinctSurfaces) has another surface there (a shelf board
  // 3.7 cm under a box top, its offset measured to 1.2 mm).
  const double reach = surfaceReach(measured.offset_sigma * measured.offset_sigma);
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    if (dropped[p] || !nearPlane(planes_[p], measured)) continue;
    const double gap = std::abs(planes_[p].normal.dot(measured.centroid) + planes_[p].d);
    if (!(measured.offset_sigma > 0.0 && gap > reach)) return true;
  }
  return false;
}

bool PlaneMap::nearPlane(const DetectedPlane& known, const FramePlane& measured) const
{
  // A tilted fit of a surface turns about its points' centroid, which stays on the surface: a
  // measurement where it was made (offset_sigma > 0) is that plane's only if the plane passes
  // its centroid. Offsets at the world origin would tie a face to any near-parallel one metres
  // away (a box's back 0.08 rad off another box's side, 8 cm apart at the origin), and part a
  // far face from its own fit tilted by 0.05 rad.
  const double max_angle = kNearTolerances * params_.merge_angle;
  const double max_distance = kNearTolerances * params_.merge_distance;
  return measured.offset_sigma > 0.0
             ? unsignedAngle(known.normal, measured.normal) <= max_angle &&
                   std::abs(known.normal.dot(measured.centroid) + known.d) <= max_distance
             : withinMergeTolerances(known.normal, known.d, measured.normal, measured.d, max_angle, max_distance);
}

bool PlaneMap::samePlane(const DetectedPlane& known, const FramePlane& measured) const
{
  return withinMergeTolerances(known.normal, known.d, measured.normal, measured.d, params_.merge_angle,
                               params_.merge_distance);
}

int PlaneMap::remeasuredPlane(const FramePlane& measured) const
{
  int match = -1;
  double best_cost = 0.0;
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    if (!samePlane(planes_[p], measured)) continue;
    const double cost = mergeCost(measured, planes_[p]);
    if (match < 0 || cost < best_cost)
    {
      match = static_cast<int>(p);
      best_cost = cost;
    }
  }
  return match;
}

bool PlaneMap::remeasured(const DetectedPlane& plane, const std::vector<FramePlane>& frame_planes) const
{
  return std::any_of(frame_planes.begin(), frame_planes.end(),
                     [&](const FramePlane& measured) { return samePlane(plane, measured); });
}

bool PlaneMap::vouchesForOneSurface(const FramePlane& measured, const std::vector<FramePlane>& frame_planes) const
{
  // A snap whose own normal is too noisy to be reported at first sight measured an offset along
  // a borrowed direction that its blocks could not check (a box face given another box's normal,
  // a wide cylinder's strip a wall's): it votes, but does not make its plane one to keep out of
  // view. Development D (seeds 700-899) kept such planes for the rest of a tour.
  if (!measured.measuresOneSurface()) return false;
  const bool snapped = measured.parallel && !measured.blocks.empty();
  return !snapped || preciseAtFirstSight(measured, frame_planes);
}

void PlaneMap::matchIds(const std::vector<HoughPeak>& peaks, const Eigen::Vector3d& camera_position, double stamp)
{
  // Each peak takes the id of the closest previous plane it is similar to.
  std::vector<DetectedPlane> previous;
  previous.swap(planes_);
  std::vector<bool> taken(previous.size(), false);
  for (const HoughPeak& peak : peaks)
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

}

void PlaneMap::carryBeliefs()
{
  // A new plane starts at PlaneBelief's start, a plane that left the map takes its belief along.
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

void PlaneMap::countOneSurfaceMeasurements(const std::vector<FramePlane>& frame_planes)
{
  for (const DetectedPlane& plane : planes_)
    if (std::any_of(frame_planes.begin(), frame_planes.end(), [&](const FramePlane& measured) {
          return samePlane(plane, measured) && vouchesForOneSurface(measured, frame_planes);
        }))
      ++beliefs_[plane.id].one_surface_measurements;
}

void PlaneMap::observe(const std::vector<int>& support, const std::vector<int>& block_labels, const FrameData& frame,
                       double stamp)
{
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    planes_[p].support = support[p];
    if (planes_[p].support >= params_.min_support) planes_[p].last_seen = stamp;
  }
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
  for (size_t b = 0; b < block_labels.size(); ++b)
  {
    if (block_labels[b] < 0) continue;
    if (block_labels[b] != last_id)  // neighbouring blocks mostly share a plane
    {
      last_id = block_labels[b];
      target = &by_id.at(last_id);
    }
    const Eigen::Vector3d centroid = frame.camera_to_world * frame.blocks[b].centroid;
    target->first->add(centroid, target->second->normal, target->second->d, frame_count_, fade);
  }
  extents_.swap(extents);
}

const PlaneExtent* PlaneMap::extent(int id) const
{
  const auto it = extents_.find(id);
  return it == extents_.end() ? nullptr : &it->second;
}

float PlaneMap::extentFade() const
{
  // By evidence, where a plane was seen stays known until the plane goes.
  return params_.forgetting == kForgetByEvidence ? 0.0f : static_cast<float>(params_.thinning_rate);
}

void PlaneMap::clearPeakCells(const Eigen::Vector3d& hough)
{
  forPeakCells(hough, [&](int x, int y, int z) {
    const float v = global_.value(x, y, z);
    if (v > 0.0f) global_.add(x, y, z, -v);
  });
}

void PlaneMap::forPeakCells(const Eigen::Vector3d& hough, const std::function<void(int, int, int)>& f) const
{
  const int r = voting_.blurRadius() + params_.peak_window / 2 + 1;
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
}

void PlaneMap::thinByEvidence(float cap, const std::vector<FramePlane>& frame_planes)
{
  // The cells around each established map plane's peak (its blur and peak window, and the
  // mirrored copy near the border) are kept as they are, a gone plane's are cleared; a plane
  // not yet established thins like everything else, a tentative one faster.
  std::vector<std::pair<Eigen::Vector3i, float>> kept;
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    const auto belief = beliefs_.find(planes_[p].id);
    // A gone plane's whole window is cleared, a neighbour's votes within it too: two peaks
    // that close pulled each other's means, so the neighbour restarts from the frames.
    if (belief != beliefs_.end() && belief->second.gone())
      clearPeakCells(planes_[p].hough);
    else if (belief != beliefs_.end() && belief->second.established())
      forOwnPeakCells(p, [&](int x, int y, int z) {
        const float v = global_.value(x, y, z);
        if (v > 0.0f) kept.emplace_back(Eigen::Vector3i(x, y, z), v);
      });
  }
  // A tentative plane (no frame after its first confirmed it) that this frame does not measure
  // again loses half a vote, thinning included: one view's hypothesis leaves unless seen again,
  // as a tracker's tentative tracks do (after the established planes' cells are noted above).
  const float tentative_fade = static_cast<float>(std::max(0.0, PlaneBelief::kTentativeFade - params_.thinning_rate));
  for (size_t p = 0; p < planes_.size(); ++p)
  {
    const auto belief = beliefs_.find(planes_[p].id);
    if (belief == beliefs_.end() || !belief->second.tentative() || remeasured(planes_[p], frame_planes)) continue;
    forOwnPeakCells(p, [&](int x, int y, int z) {
      const float v = global_.value(x, y, z);
      if (v > 0.0f) global_.add(x, y, z, -std::min(v, tentative_fade));
    });
  }
  global_.thin(static_cast<float>(params_.thinning_rate), cap);
  for (const auto& cell : kept)
  {
    const float now = global_.value(cell.first.x(), cell.first.y(), cell.first.z());
    if (now < cell.second) global_.add(cell.first.x(), cell.first.y(), cell.first.z(), cell.second - now);
  }
}

std::vector<std::vector<Eigen::Vector3d>> PlaneMap::regions(const DetectedPlane& plane) const
{
  const PlaneExtent* e = extent(plane.id);
  return e ? e->regions(frame_count_, extentFade()) : std::vector<std::vector<Eigen::Vector3d>>();
}

std::vector<PlaneOutline> PlaneMap::outlines(const DetectedPlane& plane) const
{
  const PlaneExtent* e = extent(plane.id);
  return e ? e->outlines(frame_count_, extentFade()) : std::vector<PlaneOutline>();
}

std::vector<Eigen::Vector3d> PlaneMap::hull(const DetectedPlane& plane) const
{
  const PlaneExtent* e = extent(plane.id);
  return e ? e->hull(frame_count_, extentFade()) : std::vector<Eigen::Vector3d>();
}

}  // namespace hough_plane_detector
