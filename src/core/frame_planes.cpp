#include "hough_plane_detector/core/frame_planes.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include <Eigen/Eigenvalues>

#include "hough_plane_detector/core/block_regions.h"
#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{

namespace
{
constexpr double kMinSnapInlierShare = 0.8;  // snapping: points that must lie on the parallel plane
constexpr double kEdgeOnOffsetFloor = 0.001;  // m: an edge-on block's offset is never judged finer than this
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
    case CandidateVerdict::kNormalUndetermined: return "normal undetermined";
  }
  return "unknown";
}

FramePlaneFitter::FramePlaneFitter(const DetectorParams& params, const HoughParameterization& param, FrameData& frame,
                                   const PlanarityTests& tests)
  : params_(params), param_(param), frame_(frame), tests_(tests)
{
}

PointMoments FramePlaneFitter::collectPlaneBlocks(const Eigen::Vector3d& normal, double d,
                                                 const std::vector<int>& windows, std::vector<int>& blocks,
                                                 bool tight)
{
  // Blocks covered by the windows, each once, whose points lie on the plane.
  const int k = params_.normal_window / blockSize(params_.normal_window, params_.normal_stride);
  const int bx_count = frame_.normals.blocksX();
  collected_.clear(static_cast<size_t>(bx_count) * frame_.normals.blocksY());
  // The plane in the camera frame, to test block centroids without transforming blocks.
  const Eigen::Vector3d n_cam = frame_.normalInCamera(normal);
  const double d_cam = frame_.dInCamera(normal, d);
  PointMoments moments;
  blocks.clear();
  for (int s : windows)
    for (int by = frame_.samples[s].window_y; by < frame_.samples[s].window_y + k; ++by)
      for (int bx = frame_.samples[s].window_x; bx < frame_.samples[s].window_x + k; ++bx)
      {
        const int b = by * bx_count + bx;
        if (!collected_.insertNew(b)) continue;
        const BlockInfo& info = frame_.blocks[b];
        if (!info.valid || (!frame_.block_claim.empty() && frame_.block_claim[b])) continue;
        const double residual = std::abs(n_cam.dot(info.centroid) + d_cam);
        // Tight: drops surfaces that merely cross the infinite plane along a line.
        if (residual > (tight ? std::min(params_.support_distance, info.tight_residual) : params_.support_distance))
          continue;
        // A block straddling an edge keeps its centroid near the plane while a few far points
        // would dominate the fit's moments: its spread along the normal must look like noise.
        if (n_cam.dot(info.covariance * n_cam) > info.thickness_limit) continue;
        moments.add(frame_.normals.block(bx, by));
        blocks.push_back(b);
      }
  return moments;
}

void FramePlaneFitter::fitWindows(const std::vector<HoughPeak>& peaks, const std::vector<DetectedPlane>& map_planes,
                                  std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates)
{
  // Greedy, strongest first: a peak takes the windows that agree with it and no earlier
  // plane took, is refined by a least-squares fit to their points, and keeps them. Weaker
  // echoes of the same plane find nothing left; refined per-frame planes that agree to a
  // fraction of a cell keep the global peaks sharp.
  std::vector<char> claimed(frame_.samples.size(), 0);
  frame_.block_claim.assign(static_cast<size_t>(frame_.normals.blocksX()) * frame_.normals.blocksY(), 0);
  std::vector<int> windows, blocks;
  for (const HoughPeak& peak : peaks)
  {
    Eigen::Vector3d normal = peak.normal;
    double d = peak.d;
    PointMoments moments, weighted;  // weighted: of the final blocks, reused by the planarity test
    CandidateVerdict verdict = refineOnWindows(claimed, normal, d, windows, blocks, moments, weighted);
    if (verdict == CandidateVerdict::kAccepted && !tests_.isPlanarFit(weighted, blocks))
      verdict = CandidateVerdict::kCentroidsOffPlane;
    else if (verdict == CandidateVerdict::kAccepted && !tests_.halvesAgree(blocks, 0, blocks.size(), params_.merge_angle))
      verdict = CandidateVerdict::kHalvesDisagree;
    std::vector<int> snap_blocks;
    const bool snapped = verdict == CandidateVerdict::kAccepted &&
                         snapToKnownDirection(normal, d, blocks, map_planes, planes, &snap_blocks);
    if (verdict == CandidateVerdict::kAccepted && !snapped && !normalDetermined(tests_.normalUncertainty(blocks)))
      verdict = CandidateVerdict::kNormalUndetermined;
    candidates.push_back({normal, d, peak.value, moments.count, verdict});
    if (verdict != CandidateVerdict::kAccepted) continue;
    const double first_sight_points = tests_.firstSightPoints(blocks);  // of the tight fit, as `moments`
    FramePlane refined;
    describeMeasurement(refined, blocks);
    // Claim everything within support_distance, not just the tight fit, so that leftovers
    // around an accepted plane cannot pose as a slightly tilted second one.
    for (int s : windows) claimed[s] = 1;
    for (int b : blocks) frame_.block_claim[b] = 1;
    collectPlaneBlocks(normal, d, windows, blocks, false);
    for (int b : blocks) frame_.block_claim[b] = 1;
    refined.normal = normal;
    refined.d = d;
    refined.hough = param_.toHough(normal, d);
    refined.value = peak.value;
    refined.support = moments.count;
    refined.parallel = snapped;
    refined.first_sight_points = first_sight_points;
    if (snapped) recordOwnNormal(refined, snap_blocks);
    planes.push_back(refined);
  }
}

CandidateVerdict FramePlaneFitter::refineOnWindows(const std::vector<char>& claimed, Eigen::Vector3d& normal, double& d,
                                                   std::vector<int>& windows, std::vector<int>& blocks,
                                                   PointMoments& moments, PointMoments& weighted)
{
  const double overlap = static_cast<double>(params_.normal_stride * params_.normal_stride) /
                         (params_.normal_window * params_.normal_window);
  const double cos_limit = std::cos(params_.support_angle);
  for (int pass = 0; pass < 3; ++pass)
  {
    windows.clear();
    double window_points = 0.0;
    for (size_t s = 0; s < frame_.samples.size(); ++s)
    {
      if (claimed[s] || std::abs(frame_.samples[s].normal.dot(normal)) < cos_limit) continue;
      if (std::abs(normal.dot(frame_.samples[s].centroid) + d) <= params_.support_distance)
      {
        windows.push_back(static_cast<int>(s));
        window_points += frame_.samples[s].count * overlap;
      }
    }
    // Overlapping windows count their points about once each: too few, no fit needed.
    if (window_points < params_.min_support)
    {
      moments = PointMoments();
      return CandidateVerdict::kTooFewPoints;
    }
    moments = collectPlaneBlocks(normal, d, windows, blocks, pass > 0);
    if (moments.count < std::max(3, params_.min_support)) return CandidateVerdict::kTooFewPoints;
    moments = tests_.keepFlatComponents(blocks, params_.merge_angle, 1);
    if (moments.count < std::max(3, params_.min_support)) return CandidateVerdict::kCurvedPatches;
    weighted = tests_.weightedMoments(blocks);
    const PointMoments world = weighted.transformed(frame_.camera_to_world);
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
  return CandidateVerdict::kAccepted;
}

void FramePlaneFitter::growRegions(const std::vector<HoughPeak>& peaks, const std::vector<DetectedPlane>& map_planes,
                                   std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates)
{
  // Strongest first, each peak seeds regions of blocks that agree with it; each region grows
  // over the neighbouring blocks that lie on its refitted plane within their noise and is
  // kept when it is a plane by the same statistics. Blocks a kept region took are taken for
  // the weaker peaks. Then every flat block left seeds a region of its own plane: faces too
  // small for a window's vote (box sides, far shelves) are still planes of the frame.
  frame_.block_claim.assign(frame_.blocks.size(), 0);
  split_group_.assign(planes.size(), -1);
  int split_count = 0;
  std::vector<char> tried(frame_.blocks.size(), 0);
  BlockRegionGrower grower(frame_.normals, frame_.blocks, params_);
  // An accepted region's plane, snapped or not, joins `planes`; a refused one is a candidate only.
  int split_group = -1;  // the number of the split whose parts are being kept, else -1
  auto keep = [&](PlaneRegion& region, CandidateVerdict verdict, PointMoments& moments, double peak_value) {
    // The plane of the whole face, bowed edges included, as a least-squares fit to it would be.
    // The region keeps the blocks it was tested on: claiming the bowed edges too moved later
    // regions' seeds and added false planes on rendered scenes.
    if (verdict == CandidateVerdict::kAccepted)
      grower.wholeFacePlane(region, frame_.block_claim, params_.merge_angle, region.normal, region.d);
    Eigen::Vector3d normal = frame_.normalInWorld(region.normal);
    double d = frame_.dInWorld(normal, region.d);
    std::vector<int> snap_blocks;
    // A face seen edge-on cannot orient itself, but a known normal leaves only its offset to
    // measure, and along grazing rays the depth error hardly moves a point off the plane. With
    // the world's up known, gravity shares level and upright directions between surfaces (a
    // table top seen from just above it and the floor), so such a face that passes the snap's
    // tests is the known direction at its own offset.
    const bool edge_on_with_up = verdict == CandidateVerdict::kEdgeOn && params_.world_z_up;
    const bool snapped = (verdict == CandidateVerdict::kAccepted || edge_on_with_up) &&
                         snapToKnownDirection(normal, d, region.blocks, map_planes, planes, &snap_blocks,
                                              edge_on_with_up);
    if (edge_on_with_up && snapped) verdict = CandidateVerdict::kAccepted;
    // Computed once: the orientation test and the accepted plane's record both need it.
    double normal_sigma = verdict == CandidateVerdict::kAccepted ? tests_.normalUncertainty(region.blocks) : 0.0;
    bool upright = false;
    if (verdict == CandidateVerdict::kAccepted && !snapped && !normalDetermined(normal_sigma) &&
        !(upright = uprightFace(region.blocks, normal, d, normal_sigma)))
      verdict = CandidateVerdict::kNormalUndetermined;
    candidates.push_back({normal, d, peak_value, std::max(region.points, moments.count), verdict});
    // A region on one surface that its points cannot orient keeps its blocks from the next
    // regions: they would only orient them as badly.
    if (verdict == CandidateVerdict::kNormalUndetermined)
      for (int b : region.blocks) frame_.block_claim[b] = 1;
    if (verdict != CandidateVerdict::kAccepted) return;
    for (int b : region.blocks) frame_.block_claim[b] = 1;
    // A snapped plane is measured by the blocks on it, not by the rim blocks whose lean it undid.
    planes.push_back(regionPlane(normal, d, peak_value, moments.count, snapped, region.blocks, normal_sigma,
                                 snapped ? snap_blocks : region.blocks, upright));
    if (snapped) recordOwnNormal(planes.back(), snap_blocks);
    split_group_.push_back(split_group);
  };
  auto consider = [&](const std::vector<int>& seed, const Eigen::Vector3d& n_cam, double d_cam, double peak_value) {
    PlaneRegion region = grower.grow(seed, n_cam, d_cam, frame_.block_claim);
    for (int b : region.blocks) tried[b] = 1;
    for (int b : region.trimmed) tried[b] = 1;  // near this plane: no seeds of a twin
    PointMoments moments;
    CandidateVerdict verdict = testRegion(grower, region, moments);
    // A region over two surfaces is kept as the two planes it splits into; the merge below
    // leaves that pair apart (split_group_).
    std::vector<int> first, second;
    if (verdict == CandidateVerdict::kAccepted && splitMixedRegion(grower, region, first, second))
    {
      split_group = split_count++;
      for (std::vector<int>* part : {&first, &second})
      {
        PlaneRegion piece;
        piece.blocks.swap(*part);
        grower.fit(piece.blocks, piece.normal, piece.d);
        for (int b : piece.blocks) piece.points += frame_.points(b);
        PointMoments piece_moments;
        const CandidateVerdict piece_verdict = testRegion(grower, piece, piece_moments);
        keep(piece, piece_verdict, piece_moments, peak_value);
      }
      split_group = -1;
      return;
    }
    keep(region, verdict, moments, peak_value);
  };
  constexpr size_t kMinSeedBlocks = 2;
  for (const HoughPeak& peak : peaks)
  {
    const Eigen::Vector3d n_cam = frame_.normalInCamera(peak.normal);
    const double d_cam = frame_.dInCamera(peak.normal, peak.d);
    for (const std::vector<int>& seed : grower.seedComponents(n_cam, d_cam, frame_.block_claim))
    {
      if (seed.size() < kMinSeedBlocks) break;
      bool fresh = false;
      for (int b : seed) fresh |= !frame_.block_claim[b] && !tried[b];
      if (fresh) consider(seed, n_cam, d_cam, peak.value);
    }
  }
  // Leftover flat blocks, most points first, each with its own plane as the first guess.
  std::vector<int> order;
  for (size_t b = 0; b < frame_.blocks.size(); ++b)
    if (frame_.blocks[b].planar && !frame_.block_claim[b] && !tried[b]) order.push_back(static_cast<int>(b));
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return frame_.normals.block(a).count > frame_.normals.block(b).count;
  });
  for (int b : order)
  {
    if (frame_.block_claim[b] || tried[b]) continue;
    const BlockInfo& info = frame_.blocks[b];
    consider({b}, info.normal, -info.normal.dot(info.centroid), 0.0);
  }
  mergeTouchingRegions(grower, planes);
}

FramePlane FramePlaneFitter::regionPlane(const Eigen::Vector3d& normal, double d, double value, double support,
                                         bool parallel, const std::vector<int>& blocks, double normal_sigma,
                                         const std::vector<int>& measured_by, bool upright) const
{
  FramePlane plane;
  plane.upright = upright;
  plane.normal = normal;
  plane.d = d;
  plane.hough = param_.toHough(normal, d);
  plane.value = value;
  plane.support = support;
  plane.parallel = parallel;
  // A ramp's normal (5-20 deg) is not gravity's.
  plane.level_snap = parallel && params_.world_z_up && isGravityNormal(normal, params_.merge_angle);
  plane.first_sight_points = tests_.firstSightPoints(blocks);
  plane.blocks = blocks;
  plane.normal_sigma = normal_sigma;
  testFitToBlocks(plane, measured_by);
  describeMeasurement(plane, blocks);
  return plane;
}

void FramePlaneFitter::testFitToBlocks(FramePlane& plane, const std::vector<int>& blocks) const
{
  // Against the sensor's noise. It fits its blocks when their centroids lie on the plane no
  // farther than their variance says (mean chi^2 at most its expectation, 1) and the interior's
  // own plane (no rim block that may lean over a fold) is within three sigmas of the normal's
  // uncertainty: a region that took blocks of a neighbouring face or bends along a curve fails
  // one of them. It mixes surfaces when that chi^2 is beyond what noise reaches once in a
  // hundred regions; real faces (osd-learn's boxes) often fail the interior test, not this one.
  plane.fits_its_blocks = plane.mixes_surfaces = plane.level_strip = false;
  if (blocks.empty()) return;
  const Eigen::Vector3d n_cam = frame_.normalInCamera(plane.normal);
  const double mean_chi2 = tests_.centroidChi2(n_cam, frame_.dInCamera(plane.normal, plane.d), blocks);
  plane.mixes_surfaces = mean_chi2 > noiseBoundOfMeanChi2(blocks.size());
  if (mean_chi2 > 1.0) return;
  const std::vector<int> interior = interiorBlocks(blocks, frame_.blocksX(), frame_.blocksY());
  if (interior.size() < kMinInteriorBlocks)
  {
    // A strip without an interior cannot show a fold by its own plane. A level snap took its
    // direction from gravity (a tread seen as a strip, a far table top): only its offset is
    // measured, and the centroids' chi^2 has tested that.
    plane.level_strip = plane.level_snap;
    return;
  }
  Eigen::Vector3d interior_normal;
  if (!tests_.weightedMoments(interior).planeNormal(interior_normal)) return;
  // An upright plane's sigma is of its turn about the vertical: the interior is judged on that
  // turn (that it fits upright at all, uprightFace has tested).
  if (plane.upright)
  {
    const Eigen::Vector3d up = frame_.normalInCamera(Eigen::Vector3d::UnitZ());
    interior_normal = (interior_normal - up * up.dot(interior_normal)).normalized();
  }
  plane.fits_its_blocks = unsignedAngle(interior_normal, n_cam) <= 3.0 * plane.normal_sigma;
}

void FramePlaneFitter::describeMeasurement(FramePlane& plane, const std::vector<int>& blocks) const
{
  PointMoments points;
  double information = 0.0;  // of the offset: the blocks' inverse centroid variances
  for (int b : blocks)
  {
    points.add(frame_.moments(b));
    information += tests_.centroidWeight(b);
  }
  if (!(points.count > 0.0)) return;
  plane.centroid = frame_.camera_to_world * points.mean();
  plane.offset_sigma = std::sqrt(1.0 / information + kCentroidFloor);
}

void FramePlaneFitter::recordOwnNormal(FramePlane& plane, const std::vector<int>& measured_by) const
{
  PlanarityTests::OwnNormal own;
  if (!tests_.ownNormal(measured_by, own)) return;
  const Eigen::Matrix3d rotation = frame_.camera_to_world.linear();
  plane.own_normal = rotation * own.normal;
  if (plane.own_normal.dot(plane.normal) < 0.0) plane.own_normal = -plane.own_normal;
  plane.own_normal_information = rotation * own.information * rotation.transpose();
}

void FramePlaneFitter::mergeTouchingRegions(const BlockRegionGrower& grower, std::vector<FramePlane>& planes)
{
  // Two touching regions whose normals the map would keep apart are one plane when their union
  // passes the region tests and each part lies on the union's plane within its noise: a box
  // face bowed or warped by a few degrees, grown as two regions, is otherwise reported twice.
  // Folds of more than two merge_angle stay apart, as halvesAgree keeps them; a plane with a
  // known normal (snapped) measured only its offset and is left as it is. The bar (mean chi^2
  // 4 per part) tolerates warp, which the split's noise bound does not: the two parts of a
  // split were judged two surfaces and stay apart (a real floor's two regions fail the bound
  // and are joined; kinect-real, CHANGELOG).
  const int bx_count = frame_.blocksX(), by_count = frame_.blocksY();
  std::vector<int> owner(frame_.blocks.size());
  for (bool merged = true; merged;)
  {
    merged = false;
    std::fill(owner.begin(), owner.end(), -1);
    for (size_t p = 0; p < planes.size(); ++p)
      for (int b : planes[p].blocks) owner[b] = static_cast<int>(p);
    std::set<std::pair<int, int>> touching;
    auto touch = [&](int a, int b) {
      if (owner[a] >= 0 && owner[b] >= 0 && owner[a] != owner[b])
        touching.emplace(std::min(owner[a], owner[b]), std::max(owner[a], owner[b]));
    };
    for (int y = 0; y < by_count; ++y)
      for (int x = 0; x < bx_count; ++x)
      {
        const int b = y * bx_count + x;
        if (x + 1 < bx_count) touch(b, b + 1);
        if (y + 1 < by_count) touch(b, b + bx_count);
      }
    for (const auto& pair : touching)
    {
      FramePlane& kept = planes[pair.first];
      const FramePlane& other = planes[pair.second];
      if (kept.parallel || other.parallel || unsignedAngle(kept.normal, other.normal) > 2.0 * params_.merge_angle)
        continue;
      if (split_group_[pair.first] >= 0 && split_group_[pair.first] == split_group_[pair.second]) continue;
      PlaneRegion region;
      region.blocks = kept.blocks;
      region.blocks.insert(region.blocks.end(), other.blocks.begin(), other.blocks.end());
      for (int b : region.blocks) region.points += frame_.points(b);
      region.normal = frame_.normalInCamera(kept.normal);
      region.d = frame_.dInCamera(kept.normal, kept.d);
      PointMoments moments;
      if (testRegion(grower, region, moments) != CandidateVerdict::kAccepted) continue;
      const double normal_sigma = tests_.normalUncertainty(region.blocks);
      if (!normalDetermined(normal_sigma) ||
          tests_.centroidChi2(region.normal, region.d, kept.blocks) > kMaxMeanCentroidChi2 ||
          tests_.centroidChi2(region.normal, region.d, other.blocks) > kMaxMeanCentroidChi2)
        continue;
      const Eigen::Vector3d normal = frame_.normalInWorld(region.normal);
      kept = regionPlane(normal, frame_.dInWorld(normal, region.d), std::max(kept.value, other.value), moments.count,
                         false, region.blocks, normal_sigma, region.blocks);
      planes.erase(planes.begin() + pair.second);
      split_group_.erase(split_group_.begin() + pair.second);
      merged = true;
      break;  // indices moved: list the touching pairs again
    }
  }
}

bool FramePlaneFitter::splitMixedRegion(const BlockRegionGrower& grower, const PlaneRegion& region,
                                        std::vector<int>& first, std::vector<int>& second) const
{
  // A region that drifted over two surfaces meeting at an edge (two stacked boxes' backs a few
  // degrees apart) lies off its plane beyond its blocks' noise. Two planes fitted by
  // alternating assignment (each block to the plane nearer it), started from the region's
  // halves along each of its two in-plane axes, explain it when each part, connected, lies on
  // its own plane within that noise. The parts are returned without the blocks on neither.
  const std::vector<int>& blocks = region.blocks;
  if (blocks.size() < 2 * kMinInteriorBlocks) return false;
  if (tests_.centroidChi2(region.normal, region.d, blocks) <= noiseBoundOfMeanChi2(blocks.size())) return false;
  // The largest 4-connected component of a part: blocks near the line where the two planes
  // cross lie on both within their noise and may be assigned across it.
  BlockComponents components;
  auto largestComponent = [&](const std::vector<int>& part) {
    std::vector<int> sorted = part, best;
    std::sort(sorted.begin(), sorted.end());
    components.forEach(sorted, frame_.blocksX(), frame_.blocksY(), [&](const std::vector<int>& component) {
      if (component.size() > best.size()) best = component;
    });
    return best;
  };
  // Alternating assignment from a first split; the parts' summed chi^2 when both fit, else none.
  auto refine = [&](std::vector<int>& a, std::vector<int>& b) {
    constexpr int kMaxIterations = 10;
    Eigen::Vector3d n_a = region.normal, n_b = region.normal;
    double d_a = region.d, d_b = region.d;
    for (int iteration = 0; iteration <= kMaxIterations; ++iteration)
    {
      if (a.size() < kMinInteriorBlocks || b.size() < kMinInteriorBlocks) return -1.0;
      if (!grower.fit(a, n_a, d_a) || !grower.fit(b, n_b, d_b)) return -1.0;
      std::vector<int> next_a, next_b;
      for (int block : blocks)
      {
        const Eigen::Vector3d& c = frame_.blocks[block].centroid;
        (std::abs(n_a.dot(c) + d_a) <= std::abs(n_b.dot(c) + d_b) ? next_a : next_b).push_back(block);
      }
      if (next_a == a) break;
      a.swap(next_a);
      b.swap(next_b);
    }
    if (!grower.fit(a, n_a, d_a) || !grower.fit(b, n_b, d_b)) return -1.0;
    // Blocks near the line where the two planes cross lie on both within their noise, and the
    // assignment by distance scatters them across it. Each part is its largest connected piece
    // grown over the blocks that touch it and lie on its plane within three sigmas; it must be
    // one piece give or take a tenth of its blocks, which then lie on neither piece and are left out.
    const int bx_count = frame_.blocksX(), by_count = frame_.blocksY();
    std::vector<signed char> owner(frame_.blocks.size(), -1);
    for (int block : largestComponent(a)) owner[block] = 0;
    for (int block : largestComponent(b)) owner[block] = 1;
    const Eigen::Vector3d normals[2] = {n_a, n_b};
    const double offsets[2] = {d_a, d_b};
    auto distance = [&](int block, int part) {
      return normals[part].dot(frame_.blocks[block].centroid) + offsets[part];
    };
    auto touches = [&](int block, int part) {
      bool touching = false;
      forEachNeighbour(block, bx_count, by_count, [&](int neighbour) { touching |= owner[neighbour] == part; });
      return touching;
    };
    for (bool grew = true; grew;)
    {
      grew = false;
      for (int block : blocks)
      {
        if (owner[block] >= 0) continue;
        const int nearer = std::abs(distance(block, 0)) <= std::abs(distance(block, 1)) ? 0 : 1;
        for (int part : {nearer, 1 - nearer})
          if (touches(block, part) && std::pow(distance(block, part), 2) <= 9.0 * tests_.centroidVariance(block))
          {
            owner[block] = static_cast<signed char>(part);
            grew = true;
            break;
          }
      }
    }
    constexpr double kMaxLeftOutShare = 0.1;
    std::vector<int> pieces[2];
    size_t left_out[2] = {0, 0};  // of each part as assigned
    double left_out_chi2 = 0.0;
    std::vector<char> in_a(frame_.blocks.size(), 0);
    for (int block : a) in_a[block] = 1;
    for (int block : blocks)
    {
      if (owner[block] >= 0)
      {
        pieces[owner[block]].push_back(block);
        continue;
      }
      ++left_out[in_a[block] ? 0 : 1];
      left_out_chi2 += std::min(std::pow(distance(block, 0), 2), std::pow(distance(block, 1), 2)) / tests_.centroidVariance(block);
    }
    if (left_out[0] > kMaxLeftOutShare * a.size() || left_out[1] > kMaxLeftOutShare * b.size()) return -1.0;
    if (pieces[0].size() < kMinInteriorBlocks || pieces[1].size() < kMinInteriorBlocks) return -1.0;
    if (!grower.fit(pieces[0], n_a, d_a) || !grower.fit(pieces[1], n_b, d_b)) return -1.0;
    const double chi2_a = tests_.centroidChi2(n_a, d_a, pieces[0]), chi2_b = tests_.centroidChi2(n_b, d_b, pieces[1]);
    if (chi2_a > noiseBoundOfMeanChi2(pieces[0].size()) || chi2_b > noiseBoundOfMeanChi2(pieces[1].size())) return -1.0;
    a.swap(pieces[0]);
    b.swap(pieces[1]);
    return chi2_a * a.size() + chi2_b * b.size() + left_out_chi2;  // of the whole region, as split
  };
  PointMoments centroids;
  for (int block : blocks) centroids.add(centroidMoments(frame_.moments(block)));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(centroids.covariance());
  const Eigen::Vector3d mean = centroids.mean();
  double best = -1.0;
  for (int axis = 1; axis <= 2; ++axis)
  {
    const Eigen::Vector3d along = solver.eigenvectors().col(axis);
    std::vector<int> a, b;
    for (int block : blocks) (along.dot(frame_.blocks[block].centroid - mean) >= 0.0 ? a : b).push_back(block);
    const double chi2 = refine(a, b);
    if (chi2 >= 0.0 && (best < 0.0 || chi2 < best))
    {
      best = chi2;
      first.swap(a);
      second.swap(b);
    }
  }
  return best >= 0.0;
}

CandidateVerdict FramePlaneFitter::testRegion(const BlockRegionGrower& grower, PlaneRegion& region,
                                              PointMoments& moments) const
{
  // Each test against the sensor's noise at the blocks' depths; the fit is of the flat
  // components kept.
  const double min_points = std::max(3, params_.min_support);
  if (region.points < min_points) return CandidateVerdict::kTooFewPoints;
  // A region that ends where its surface does is a whole face, which may bow as real faces do
  // (kSurfaceWarp); one that runs on is judged with its continuation (continuesAndBends).
  const double max_sag =
      grower.endsWhereItsSurfaceDoes(region.blocks, region.normal, region.d) ? kSurfaceWarp : kMaxPlaneSag;
  int flat_patches = 0;
  if ((moments = tests_.keepFlatComponents(region.blocks, params_.merge_angle, 1, nullptr, &flat_patches, max_sag))
          .count < min_points)
    return CandidateVerdict::kCurvedPatches;
  if (!grower.fit(region.blocks, region.normal, region.d)) return CandidateVerdict::kTooFewPoints;
  if (grower.seenEdgeOn(region.blocks, region.normal)) return CandidateVerdict::kEdgeOn;
  if (grower.normalsTurn(region.blocks, region.normal, max_sag) ||
      grower.centroidsBend(region.blocks, region.normal, region.d, max_sag))
    return CandidateVerdict::kCurvedPatches;
  if (!tests_.isPlanarFit(tests_.weightedMoments(region.blocks), region.blocks))
    return CandidateVerdict::kCentroidsOffPlane;
  if (grower.continuesAndBends(region.blocks, region.normal, region.d)) return CandidateVerdict::kCurvedPatches;
  // One patch left has passed this very test (the same blocks in the same order) just above.
  if (flat_patches > 1 && !tests_.halvesAgree(region.blocks, 0, region.blocks.size(), params_.merge_angle, max_sag))
    return CandidateVerdict::kHalvesDisagree;
  return CandidateVerdict::kAccepted;
}

bool FramePlaneFitter::uprightFace(const std::vector<int>& blocks, Eigen::Vector3d& normal, double& d,
                                   double& normal_sigma) const
{
  // With the world's up known, gravity stands walls, doors and the sides of boxes upright: a
  // face its points leave unoriented but that fits an upright plane has one angle left to
  // measure, its turn about the vertical.
  if (!params_.world_z_up) return false;
  Eigen::Vector3d n_cam;
  double d_cam = 0.0, sigma = 0.0;
  if (!tests_.uprightNormal(blocks, frame_.normalInCamera(Eigen::Vector3d::UnitZ()), n_cam, d_cam, sigma) ||
      !normalDetermined(sigma))
    return false;
  normal = frame_.normalInWorld(n_cam);
  normal.z() = 0.0;  // upright to the last bit, as the snap's level normals are level
  normal.normalize();
  d = frame_.dInWorld(normal, d_cam);
  normal_sigma = sigma;
  return true;
}

bool FramePlaneFitter::normalDetermined(double normal_sigma) const
{
  // Within merge_angle at two sigmas, so that every frame's fit of the surface lands on one
  // Hough peak; a plane the points cannot orient (a strip along a shelf's edge) is no plane.
  return normal_sigma <= params_.merge_angle / 2.0;
}

const Eigen::Vector3d* FramePlaneFitter::knownNormalFor(const Eigen::Vector3d& normal, const Eigen::Vector3d& centroid,
                                                       const std::vector<DetectedPlane>& map_planes,
                                                       const std::vector<FramePlane>& planes,
                                                       bool* on_that_plane) const
{
  // A piece of a known plane is most likely that surface re-measured: its direction comes
  // before a parallel plane's elsewhere that happens to be closer to the piece's noisy fit
  // (a far strip of a wall fitted 0.05 rad off, nearer a box face's normal than the wall's).
  const Eigen::Vector3d* closest = nullptr;
  const Eigen::Vector3d* closest_on = nullptr;
  double closest_angle = params_.snap_angle, closest_on_angle = params_.snap_angle;
  auto consider = [&](const Eigen::Vector3d& known_normal, double known_d) {
    const double angle = unsignedAngle(known_normal, normal);
    if (angle < closest_angle)
    {
      closest_angle = angle;
      closest = &known_normal;
    }
    if (angle < closest_on_angle && std::abs(known_normal.dot(centroid) + known_d) <= params_.merge_distance)
    {
      closest_on_angle = angle;
      closest_on = &known_normal;
    }
  };
  for (const DetectedPlane& plane : map_planes) consider(plane.normal, plane.d);
  // With the world's up known, a direction off the vertical comes from the map only: this
  // frame's other regions share its depth errors (a structured-light camera's are correlated
  // over many pixels and tilt a face's fit without residuals), so their directions are no
  // independent reference, while the map's were measured in earlier frames and gravity's is
  // exact. Without an up this frame's surfaces are all there is (a box top on its table).
  for (const FramePlane& plane : planes)
    if (!params_.world_z_up || isLevelSurfaceNormal(plane.normal)) consider(plane.normal, plane.d);
  if (on_that_plane) *on_that_plane = closest_on != nullptr;
  return closest_on ? closest_on : closest;
}

bool FramePlaneFitter::snapToKnownDirection(Eigen::Vector3d& normal, double& d, const std::vector<int>& blocks,
                                            const std::vector<DetectedPlane>& map_planes,
                                            const std::vector<FramePlane>& planes,
                                            std::vector<int>* measured_by, bool seen_edge_on) const
{
  // A small or far plane nearly parallel to a known one (a stair tread to the floor, a shelf
  // top) is fitted with a tilt of a few degrees: blocks of the surfaces it meets lean on its
  // edges. If most of its points lie on a plane of the known normal within their noise, that
  // plane, with one parameter fewer, is the better model.
  if (blocks.empty()) return false;
  PointMoments piece;
  for (int b : blocks) piece.add(frame_.moments(b));
  bool on_known_plane = false;
  const Eigen::Vector3d* known_normal =
      knownNormalFor(normal, frame_.camera_to_world * piece.mean(), map_planes, planes, &on_known_plane);
  if (!known_normal) return false;
  const Eigen::Vector3d known = known_normal->dot(normal) >= 0.0 ? *known_normal : Eigen::Vector3d(-*known_normal);
  const Eigen::Vector3d n_cam = frame_.normalInCamera(known);
  // The offset most points agree on (a median: the leaning blocks are outliers), then the
  // blocks within three of their sigmas of it.
  auto points = [&](int b) { return frame_.normals.block(b).count; };
  std::vector<std::pair<double, double>> offsets;  // camera-frame d of each block, its points
  double total = 0.0;
  for (int b : blocks)
  {
    offsets.emplace_back(-n_cam.dot(frame_.blocks[b].centroid), points(b));
    total += points(b);
  }
  const double median = weightedMedian(offsets, total);
  std::vector<int> inliers;
  double inlier_points = 0.0, weight_sum = 0.0, weighted_d = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& info = frame_.blocks[b];
    // A plane through (or near) the sensor images as a line, its horizon: the points of any
    // surface in a block across that line lie near it, but scatter along the normal by the
    // block's footprint, not by their depth noise as a face's points do.
    if (seen_edge_on && !tests_.isThinAlong(b, n_cam)) continue;
    const double offset = -n_cam.dot(info.centroid);
    // Along a grazing ray only the sine's share of the depth error lies along the normal: a
    // block of the surface behind an edge-on face is far off its plane in that noise.
    double variance = tests_.centroidVariance(b);
    if (seen_edge_on)
    {
      const double sine = n_cam.dot(info.ray);
      variance = variance * sine * sine + kEdgeOnOffsetFloor * kEdgeOnOffsetFloor;
    }
    if (std::abs(offset - median) > 3.0 * std::sqrt(variance)) continue;
    inliers.push_back(b);
    inlier_points += points(b);
    weight_sum += info.fit_weight;
    weighted_d += info.fit_weight * offset;
  }
  if (inlier_points < kMinSnapInlierShare * total) return false;
  const double d_cam = weighted_d / weight_sum;
  if (tests_.centroidChi2(n_cam, d_cam, inliers) > kMaxMeanCentroidChi2) return false;
  // The known normal must also explain the inliers about as well as their own best plane: a
  // likelihood-ratio test (2 degrees of freedom, the normal's), else a box face a few degrees
  // off an older box's would take its direction. Judged on the interior: rim blocks straddling
  // a fold (a ramp's foot, a tread's nosing) are the lean the snap exists to undo.
  const PlanarityTests::NormalExplanation explained = tests_.explainNormal(n_cam, inliers, true);
  // Gravity keeps level surfaces parallel to a fraction of a degree (floors, treads, ramps,
  // table and shelf tops); faces of other directions are parallel by design or by chance (boxes
  // at any yaw). A snap onto those must also hold against the face's own scatter, where that is
  // one face's: a grown region's. The windows' blocks are all within support_distance of the
  // peak's plane (a cabinet front and a desk's edge 3 cm before it): their scatter is the mix.
  if (!tests_.acceptsKnownNormal(explained, known)) return false;
  // Without the world's up no direction is known to be level, so the direction of another
  // surface (the piece off its plane) may be parallel only by chance (box faces at any yaw):
  // it too must hold against a grown region's own scatter. Its own surface re-measured need not.
  if (!params_.world_z_up && params_.region_growing && !on_known_plane && !explained.interior_within_own_scatter)
    return false;
  // Near the sensor the rim blocks are oriented too; if with them the known normal no longer
  // explains the face, its own normal is the better model, when the points determine it.
  if (!explained.with_oriented_rim && normalDetermined(tests_.normalUncertainty(inliers))) return false;
  normal = known;
  d = frame_.dInWorld(known, d_cam);
  if (measured_by) *measured_by = std::move(inliers);
  return true;
}

}  // namespace hough_plane_detector
