#include "hough_plane_detector/core/planarity_tests.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <Eigen/Eigenvalues>

#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{

PlanarityTests::PlanarityTests(const DetectorParams& params, const FrameData& frame) : params_(params), frame_(frame) {}

bool PlanarityTests::isPlanarFit(const PointMoments& moments, const std::vector<int>& blocks) const
{
  // A curved surface (a pillar, a ball) yields planar windows and even a whole fit within the
  // sensor noise; but block centroids, where noise averages out, bend away from the fit.
  // Each must lie on it as closely as the block's own scatter allows (chi^2 per block).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(moments.covariance());
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  const Eigen::Vector3d mean = moments.mean();
  double chi2 = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& info = frame_.blocks[b];
    const double count = frame_.normals.block(b).count;
    // The block's own scatter along the plane normal: noise if it lies on the plane.
    const double own_variance = std::max(0.0, normal.dot(info.covariance * normal));
    const double step = frame_.noise.quantizationStep(info.centroid.z());
    const double distance = normal.dot(info.centroid - mean);
    chi2 += distance * distance / (own_variance / count + step * step / 12.0 + kCentroidFloor);
  }
  if (!blocks.empty() && chi2 / blocks.size() > kMaxMeanCentroidChi2) return false;
  return true;
}


bool PlanarityTests::halvesAgree(const std::vector<int>& blocks, size_t begin, size_t end, double max_angle,
                                 double max_sag) const
{
  // A curved strip fits a plane within the noise, but its two halves tilt apart.
  // Each block's centroid moments, centroid and variance, read once for both axes.
  struct Centroid
  {
    PointMoments moments;
    Eigen::Vector3d position;
    double variance;
  };
  std::vector<Centroid> centroids;
  centroids.reserve(end - begin);
  PointMoments all;
  for (size_t i = begin; i < end; ++i)
  {
    const PointMoments moments = centroidMoments(frame_.moments(blocks[i]));
    centroids.push_back({moments, moments.mean(), centroidVariance(blocks[i])});
    all.add(moments);
  }
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
    for (const Centroid& centroid : centroids)
    {
      const int h = direction.dot(centroid.position - mean) >= 0.0 ? 1 : 0;
      halves[h].add(centroid.moments);
      half_variance[h] += centroid.variance;
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
    if (tilt <= max_angle) continue;
    // Windows' fit: the paper's fixed tolerance. Regions: beyond what the fits' noise explains
    // and bending faster than a plane may (a real box face bows by 1/m) or folding by more
    // than two Hough merges apart (a floor running into a ramp, at any size).
    if (!params_.region_growing) return false;
    const double separation = (halves[1].mean() - halves[0].mean()).norm();
    const bool bends = tilt > 2.0 * max_angle || tilt > kMaxPlaneCurvature * separation;
    // The halves' centres lie half the width apart, so the sag is tilt * separation / 2.
    if (tilt > 3.0 * std::sqrt(tilt_variance) && bends && tilt * separation / 2.0 > max_sag) return false;
  }
  return true;
}

double PlanarityTests::normalUncertainty(const std::vector<int>& blocks) const
{
  // Each centroid weighted by the inverse of its own variance (quantization and systematic
  // error included: they do not average out within a block).
  const PointMoments moments = noiseWeightedCentroids(blocks);
  if (blocks.size() < 3 || moments.count <= 0.0) return M_PI / 2;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(moments.covariance());
  // The tilt about the long axis is fixed by the spread across it (the middle axis).
  return tiltUncertainty(blocks, moments.mean(), solver.eigenvectors().col(1));
}

double PlanarityTests::tiltUncertainty(const std::vector<int>& blocks, const Eigen::Vector3d& mean,
                                       const Eigen::Vector3d& axis) const
{
  // That must not hinge on a few blocks (a row along a shelf's edge and two off it, on the
  // wall): the most informative tenth, at least two, is left out.
  std::vector<double> information;
  information.reserve(blocks.size());
  for (int b : blocks)
  {
    const BlockInfo& info = frame_.blocks[b];
    const double weight = frame_.points(b) > 0.0 ? centroidWeight(b) : 0.0;
    const double x = axis.dot(info.centroid - mean);
    information.push_back(weight * x * x);
  }
  const size_t left_out = std::min(information.size() - 1, std::max<size_t>(2, information.size() / 10));
  std::nth_element(information.begin(), information.begin() + left_out, information.end(), std::greater<double>());
  double kept = 0.0;
  for (size_t i = left_out; i < information.size(); ++i) kept += information[i];
  return kept > 0.0 ? std::min(M_PI / 2, 1.0 / std::sqrt(kept)) : M_PI / 2;
}

bool PlanarityTests::uprightNormal(const std::vector<int>& blocks, const Eigen::Vector3d& up, Eigen::Vector3d& n_cam,
                                   double& d_cam, double& sigma) const
{
  const PointMoments moments = noiseWeightedCentroids(blocks);
  if (blocks.size() < 3 || moments.count <= 0.0) return false;
  const Eigen::Matrix3d scatter = moments.covariance();
  // The turn the points leave free is about their long axis: the constraint fixes it only when
  // that axis is nearer level than upright (a band of a wall, a box face seen far off); along
  // a tall strip (a pillar's side) it is the turn about the vertical, which stays free.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> axes;
  axes.computeDirect(scatter);
  if (std::abs(axes.eigenvectors().col(2).dot(up)) > M_SQRT1_2) return false;
  // The best plane among those whose normal lies in the level plane spanned by e1 and e2.
  const Eigen::Vector3d e1 = up.unitOrthogonal(), e2 = up.cross(e1).normalized();
  Eigen::Matrix2d level;
  level << e1.dot(scatter * e1), e1.dot(scatter * e2), e2.dot(scatter * e1), e2.dot(scatter * e2);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver;
  solver.computeDirect(level);
  const Eigen::Vector2d smallest = solver.eigenvectors().col(0);
  n_cam = (smallest.x() * e1 + smallest.y() * e2).normalized();
  const Eigen::Vector3d mean = moments.mean();
  if (n_cam.dot(mean) > 0.0) n_cam = -n_cam;  // toward the sensor at the origin
  d_cam = -n_cam.dot(mean);
  // All blocks: an interior may be one row, which any plane through it fits.
  if (snapChi2(n_cam, blocks).fixed / static_cast<double>(blocks.size()) > noiseBoundOfMeanChi2(blocks.size()))
    return false;
  sigma = tiltUncertainty(blocks, mean, up.cross(n_cam).normalized());
  return true;
}

double PlanarityTests::firstSightPoints(const std::vector<int>& blocks) const
{
  const double reference_sigma = frame_.noise.sigma(kStrongSupportDepth);
  double points = 0.0;
  for (int b : blocks)
  {
    const double sigma = frame_.noise.sigma(frame_.blocks[b].centroid.z());
    const double weight = sigma > 0.0 ? reference_sigma * reference_sigma / (sigma * sigma) : 1.0;
    points += frame_.points(b) * std::max(1.0, weight);
  }
  return points;
}

PointMoments PlanarityTests::weightedMoments(const std::vector<int>& blocks) const
{
  return weightedCentroidMoments(frame_.blocks, blocks);
}

PointMoments PlanarityTests::keepFlatComponents(std::vector<int>& blocks, double max_angle, int min_span,
                                               const std::function<bool(const std::vector<int>&)>& also,
                                               int* kept_count, double max_sag) const
{
  if (kept_count) *kept_count = 0;
  // Two pillars can share a tangent plane: each connected patch of the support must be flat
  // on its own; curved patches are dropped, tiny ones too (they cannot be tested).
  constexpr size_t kMinComponentBlocks = 4;
  const int bx_count = frame_.normals.blocksX(), by_count = frame_.normals.blocksY();
  std::vector<int> kept;
  components_.forEach(blocks, bx_count, by_count, [&](const std::vector<int>& component) {
    int x_min = bx_count, x_max = -1, y_min = by_count, y_max = -1;
    for (int b : component)
    {
      x_min = std::min(x_min, b % bx_count), x_max = std::max(x_max, b % bx_count);
      y_min = std::min(y_min, b / bx_count), y_max = std::max(y_max, b / bx_count);
    }
    const bool wide_enough = x_max - x_min + 1 >= min_span && y_max - y_min + 1 >= min_span;
    if (component.size() >= kMinComponentBlocks && wide_enough &&
        halvesAgree(component, 0, component.size(), max_angle, max_sag) && (!also || also(component)))
    {
      kept.insert(kept.end(), component.begin(), component.end());
      if (kept_count) ++*kept_count;
    }
  });
  blocks.swap(kept);
  PointMoments moments;
  for (int b : blocks) moments.add(frame_.normals.block(b));
  return moments;
}

namespace
{
// True when the blocks lie in more than one row and more than one column of the block grid.
bool spansRowsAndColumns(const std::vector<int>& blocks, int blocks_x)
{
  if (blocks.empty()) return false;
  bool rows = false, columns = false;
  for (int b : blocks)
  {
    rows |= b / blocks_x != blocks.front() / blocks_x;
    columns |= b % blocks_x != blocks.front() % blocks_x;
  }
  return rows && columns;
}
}  // namespace

PlanarityTests::NormalExplanation PlanarityTests::explainNormal(const Eigen::Vector3d& n_cam,
                                                               const std::vector<int>& blocks, bool with_rim) const
{
  NormalExplanation verdict;
  std::vector<int> tested = interiorBlocks(blocks, frame_.normals.blocksX(), frame_.normals.blocksY());
  const bool no_interior = tested.size() < kMinInteriorBlocks;
  // No interior to tell from the rim: all blocks are tested, once for both verdicts.
  if (no_interior) tested = blocks;
  SnapSums sums;
  addToSnapSums(n_cam, tested, 0, sums);
  const SnapChi2 chi2 = snapChi2Of(sums);
  verdict.interior = chi2.fixed - chi2.free <= kMaxSnapChi2Increase;
  const double free_dof = static_cast<double>(tested.size()) - 3.0;  // a plane's three parameters
  // Without an interior the scatter includes the rim's lean that a snap exists to undo; an
  // interior of one block row or column (a narrow riser's) fits a pencil of planes exactly.
  verdict.interior_within_own_scatter =
      verdict.interior && (no_interior ||
                           (chi2.fixed - chi2.free) / 2.0 <= fCriticalTwo(free_dof, 0.01) * chi2.free / free_dof ||
                           !spansRowsAndColumns(tested, frame_.normals.blocksX()));
  if (no_interior)
  {
    verdict.with_oriented_rim = verdict.interior;
    return verdict;
  }
  if (!with_rim || !verdict.interior) return verdict;
  std::vector<char> interior(frame_.blocks.size(), 0);
  for (int b : tested) interior[b] = 1;
  const size_t interior_count = tested.size();
  for (int b : blocks)
  {
    const BlockInfo& info = frame_.blocks[b];
    if (!interior[b] && info.normal_tolerance < M_PI / 2 &&
        std::abs(info.normal.dot(n_cam)) >= info.normal_tolerance_cosine)
      tested.push_back(b);
  }
  // The interior's sums go on with the rim (a region of a whole floor has thousands of blocks).
  addToSnapSums(n_cam, tested, interior_count, sums);
  const SnapChi2 with_rim_chi2 = snapChi2Of(sums);
  verdict.with_oriented_rim = with_rim_chi2.fixed - with_rim_chi2.free <= kMaxSnapChi2Increase;
  return verdict;
}

PointMoments PlanarityTests::noiseWeightedCentroids(const std::vector<int>& blocks) const
{
  PointMoments sum;
  for (int b : blocks) addNoiseWeightedCentroid(b, centroidWeight(b), sum);
  return sum;
}

void PlanarityTests::addNoiseWeightedCentroid(int b, double weight, PointMoments& sum) const
{
  PointMoments m = centroidMoments(frame_.normals.block(b));
  if (m.count <= 0.0) return;  // an empty block has no centroid
  m.scale(weight / m.count);
  sum.add(m);
}

PlanarityTests::SnapChi2 PlanarityTests::snapChi2(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const
{
  SnapSums sums;
  addToSnapSums(n_cam, blocks, 0, sums);
  return snapChi2Of(sums);
}

void PlanarityTests::addToSnapSums(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks, size_t first,
                                   SnapSums& sums) const
{
  for (size_t k = first; k < blocks.size(); ++k)
  {
    const int b = blocks[k];
    const double weight = centroidWeight(b);
    addNoiseWeightedCentroid(b, weight, sums.centroids);
    const double offset = n_cam.dot(frame_.blocks[b].centroid);
    sums.weight += weight;
    sums.offset += weight * offset;
    sums.offset_squares += weight * offset * offset;
  }
}

PlanarityTests::SnapChi2 PlanarityTests::snapChi2Of(const SnapSums& sums)
{
  // Centroids weighted by their inverse variance: the smallest eigenvalue of their scatter
  // times the total weight is the chi^2 of the best free plane; the fixed normal's best plane
  // has the weighted variance of the offsets along it.
  SnapChi2 chi2;
  if (sums.weight <= 0.0) return chi2;
  chi2.fixed = sums.offset_squares - sums.offset * sums.offset / sums.weight;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(sums.centroids.covariance());
  chi2.free = std::max(0.0, solver.eigenvalues()(0)) * sums.centroids.count;
  return chi2;
}

bool PlanarityTests::ownNormal(const std::vector<int>& blocks, OwnNormal& own) const
{
  std::vector<int> interior = interiorBlocks(blocks, frame_.normals.blocksX(), frame_.normals.blocksY());
  const std::vector<int>& fitted = interior.size() >= kMinInteriorBlocks ? interior : blocks;
  if (fitted.size() < 3) return false;
  const PointMoments sum = noiseWeightedCentroids(fitted);
  // The scatter about the weighted mean: tilting the plane by t moves a centroid x off it by
  // t . (x - mean), so the chi^2 rises by t' scatter t.
  const Eigen::Matrix3d scatter = sum.covariance() * sum.count;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(scatter);
  own.normal = solver.eigenvectors().col(0).normalized();
  own.information = scatter;
  return true;
}

bool PlanarityTests::isThinAlong(int block, const Eigen::Vector3d& n_cam) const
{
  return blockThinAlong(frame_.blocks[block], frame_.points(block), n_cam);
}

double PlanarityTests::centroidChi2(const Eigen::Vector3d& n_cam, double d_cam, const std::vector<int>& blocks) const
{
  double chi2 = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& info = frame_.blocks[b];
    const double distance = n_cam.dot(info.centroid) + d_cam;
    chi2 += distance * distance / centroidVariance(b);
  }
  return blocks.empty() ? 0.0 : chi2 / blocks.size();
}

bool PlanarityTests::fitIsParallel(const Eigen::Vector3d& n_cam, const std::vector<int>& blocks) const
{
  // Far from a Kinect an 8 x 8 block is as thick as it is wide, so a band of wall blocks at one
  // height passes for a floor-parallel patch block by block; their centroids together still
  // span the wall, not a floor.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(weightedMoments(blocks).covariance());
  return unsignedAngle(solver.eigenvectors().col(0), n_cam) <= 2.0 * params_.merge_angle;
}

}  // namespace hough_plane_detector
