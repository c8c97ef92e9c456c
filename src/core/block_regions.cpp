#include "hough_plane_detector/core/block_regions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Eigenvalues>
#include <boost/math/distributions/fisher_f.hpp>

#include "hough_plane_detector/core/plane_geometry.h"
#include "hough_plane_detector/core/symmetric_eigen.h"

namespace hough_plane_detector
{

namespace
{
constexpr double kMinBlockSigma = 0.001;   // m: no block is judged flatter than a millimetre
constexpr double kMaxNormalTolerance = 1.0;  // rad: a block's normal is never trusted less than this
constexpr double kMaxThicknessRatio = 0.25;  // noise variance over in-plane spread: beyond, no normal
constexpr double kMinRaySine = 0.1;  // rays at least ~6 deg to a plane
// Depth error that does not average out over a block (calibration residue of structured
// light, surfaces a little off flat), per squared metre of depth: 1.5 mm at 1 m.
constexpr double kSystematicPerSquareMetre = 0.0015;
// A quadric's chi^2 drop over a plane's, 3 degrees of freedom, exceeded with p = 0.001.
constexpr double kChi2DropThreeDof = 16.27;

// The value an F statistic with (3, dof) degrees of freedom exceeds with p = 0.001, as the
// quadric's chi^2 drop over 3 dof is judged. Tabled once (boost's quantile takes ~14 us); beyond
// the table it falls as 1/dof toward chi^2(3) / 3, the same test with a known variance
// (within 0.03 % of the exact value).
double lackOfFitCritical(double dof)
{
  constexpr int kTabled = 256;
  constexpr double kLimit = kChi2DropThreeDof / 3.0;
  static const std::vector<double> table = [] {
    std::vector<double> values(kTabled + 1, 0.0);
    for (int n = 1; n <= kTabled; ++n)
      values[n] = boost::math::quantile(boost::math::complement(boost::math::fisher_f(3.0, n), 0.001));
    return values;
  }();
  if (dof < 1.0) return std::numeric_limits<double>::infinity();
  if (dof <= kTabled) return table[static_cast<int>(dof)];
  return kLimit + (table[kTabled] - kLimit) * kTabled / dof;
}
}  // namespace

PointMoments centroidMoments(const PointMoments& block)
{
  PointMoments m;
  if (block.count <= 0.0) return m;
  const Eigen::Vector3d c = block.mean();
  m.count = block.count;
  m.sum = block.sum;
  m.xx = block.count * c.x() * c.x(); m.xy = block.count * c.x() * c.y(); m.xz = block.count * c.x() * c.z();
  m.yy = block.count * c.y() * c.y(); m.yz = block.count * c.y() * c.z(); m.zz = block.count * c.z() * c.z();
  return m;
}

PointMoments weightedCentroidMoments(const std::vector<BlockInfo>& info, const std::vector<int>& blocks)
{
  PointMoments sum;
  for (int b : blocks) sum.add(info[b].weighted_centroid);
  return sum;
}

void describeBlocks(const NormalEstimator& grid, const DetectorParams& params, const DepthNoiseModel& noise,
                    std::vector<BlockInfo>& info, ThreadTeam& team)
{
  info.resize(static_cast<size_t>(grid.blocksX()) * grid.blocksY());
  // Each block is described on its own; a row of blocks is one item of the team's work.
  team.forEach(grid.blocksY(), [&](int by, int) { describeBlockRow(grid, params, noise, by, info); });
}

void describeBlockRow(const NormalEstimator& grid, const DetectorParams& params, const DepthNoiseModel& noise, int by,
                      std::vector<BlockInfo>& info)
{
  const int bx_count = grid.blocksX();
  const bool noise_aware = noise.enabled();
  for (int b = by * bx_count; b < (by + 1) * bx_count; ++b)
  {
    const PointMoments& block = grid.block(b - by * bx_count, by);
    BlockInfo& i = info[b];
    i = BlockInfo();
    i.valid = block.count >= 3;
    if (!i.valid) continue;
    i.centroid = block.mean();
    i.ray = i.centroid.normalized();
    i.covariance = block.covariance();
    const double sigma = noise.sigma(i.centroid.z());
    const double step = noise.quantizationStep(i.centroid.z());
    // Quantization moves a block as a whole, so it does not average out over the block.
    i.centroid_variance = sigma * sigma / block.count + step * step / 12.0;
    // Around a fitted plane a centroid may stray by its noise and 1 cm of sensor warp.
    i.tight_residual = noise_aware ? 0.01 + 3.0 * std::sqrt(i.centroid_variance) : params.support_distance;
    i.thickness_limit = noise_aware ? 6.25 * sigma * sigma + 1e-4 : 0.25 * params.support_distance * params.support_distance;
    i.fit_weight = 1.0 / (sigma * sigma + 1e-6);
    i.random_depth_variance = std::max(0.0, sigma * sigma - step * step / 12.0);
    i.quantization_step = step;
    i.weighted_centroid = centroidMoments(block);
    i.weighted_centroid.scale(i.fit_weight);
    const double systematic = kSystematicPerSquareMetre * i.centroid.z() * i.centroid.z();
    const double block_sigma = std::max(kMinBlockSigma, sigma);
    i.region_residual = 3.0 * std::sqrt(block_sigma * block_sigma / block.count + step * step / 12.0 + systematic * systematic);
    if (!params.region_growing) continue;  // the windows' fit needs no block normals
    const SmallestEigenpair eigen = smallestEigenpair(i.covariance);
    i.normal = eigen.vector;
    if (i.normal.dot(i.centroid) > 0.0) i.normal = -i.normal;
    // Flat: thinner along its normal than three sigmas of the sensor's noise (an edge or a
    // depth jump inside the block is thicker). Its normal is then good to sigma over its
    // narrower half-width, per point.
    const Eigen::Vector3d eigenvalues = eigen.values.cwiseMax(0.0);
    i.planar = block.count >= 8 && (noise_aware ? eigenvalues(0) <= 9.0 * block_sigma * block_sigma : eigenvalues(0) <= i.thickness_limit);
    // Where the block is as thick as half its width (noise far from a Kinect) its smallest
    // eigenvector may lie in the surface: such a block is judged by its centroid alone. Both
    // come from the block's own scatter, so a sensor quieter than the model is used as it is.
    const double normal_sigma = std::sqrt(eigenvalues(0) / (std::max(1e-12, eigenvalues(1)) * block.count));
    const bool normal_informative = eigenvalues(0) < kMaxThicknessRatio * eigenvalues(1);
    i.normal_tolerance = normal_informative ? std::min(kMaxNormalTolerance, std::max(params.support_angle, 3.0 * normal_sigma))
                                            : M_PI / 2;
    i.normal_tolerance_cosine = std::cos(i.normal_tolerance);
  }
}

bool blockThinAlong(const BlockInfo& info, double points, const Eigen::Vector3d& n_cam)
{
  const double thickness = n_cam.dot(info.covariance * n_cam);
  if (!(info.random_depth_variance > 0.0) || points < 2.0) return thickness <= info.thickness_limit;
  // A depth error moves a point along its ray: by ray / ray.z per metre of depth.
  const double along_normal = n_cam.dot(info.ray) / info.ray.z();
  // The random part's sample variance (points - 1 degrees of freedom; the covariance divides
  // by the count) within its p = 0.01 bound; quantization errors lie within half a step, so
  // their variance is at most a quarter step squared (points split over two levels).
  const double random = info.random_depth_variance * noiseBoundOfMeanChi2(static_cast<size_t>(points - 1.0)) *
                        (points - 1.0) / points;
  const double bound = (random + 0.25 * info.quantization_step * info.quantization_step) * along_normal * along_normal +
                       kFaceRoughness * kFaceRoughness;
  return thickness <= std::min(bound, info.thickness_limit);
}

BlockRegionGrower::BlockRegionGrower(const NormalEstimator& grid, const std::vector<BlockInfo>& info,
                                     const DetectorParams& params)
  : grid_(grid), info_(info), params_(params)
{
}

bool BlockRegionGrower::grazes(int block, const Eigen::Vector3d& normal) const
{
  return std::abs(normal.dot(info_[block].ray)) < kMinRaySine;
}

bool BlockRegionGrower::accepts(int block, const Eigen::Vector3d& normal, double d, double warp, bool oriented_only) const
{
  const BlockInfo& i = info_[block];
  if (!i.planar) return false;
  // The distance first: it turns away most blocks of a frame (seedComponents asks them all).
  // A face's warp adds to the block's noise as an independent error.
  const double reach = warp > 0.0 ? std::sqrt(i.region_residual * i.region_residual + warp * warp) : i.region_residual;
  if (!(std::abs(normal.dot(i.centroid) + d) <= std::min(params_.support_distance, reach))) return false;
  // A thick block at a fold would pass any normal; where that matters only oriented ones join.
  if (oriented_only && i.normal_tolerance >= M_PI / 2) return false;
  if (std::abs(i.normal.dot(normal)) < i.normal_tolerance_cosine) return false;
  // Rays that graze a plane move along it with their depth error, so any surface they hit
  // lies "on" it by its centroid; but a block whose points are thin along the normal, within
  // the sine's share of their depth noise, lies on it point by point (a table top seen from
  // just above it). Without a noise model no such share is known, and no grazing block joins.
  return !grazes(block, normal) || (i.random_depth_variance > 0.0 && blockThinAlong(i, grid_.block(block).count, normal));
}

size_t BlockRegionGrower::sweep(std::vector<int>& blocks, const std::vector<char>& taken, const Eigen::Vector3d& normal,
                                double d, double warp, bool oriented_only)
{
  const int bx_count = grid_.blocksX(), by_count = grid_.blocksY();
  reached_.clear(info_.size());
  for (int b : blocks) reached_.insert(b);
  const size_t before = blocks.size();
  for (size_t head = 0; head < blocks.size(); ++head)
    forEachNeighbour(blocks[head], bx_count, by_count, [&](int nb) {
      if (taken[nb] || !reached_.insertNew(nb)) return;
      if (accepts(nb, normal, d, warp, oriented_only)) blocks.push_back(nb);
    });
  return blocks.size() - before;
}

bool BlockRegionGrower::wholeFacePlane(const PlaneRegion& region, const std::vector<char>& taken, double max_turn,
                                       Eigen::Vector3d& normal, double& d)
{
  std::vector<int> blocks = region.blocks;
  Eigen::Vector3d face_normal = region.normal;
  double face_d = region.d;
  constexpr int kMaxSweeps = 3;
  for (int s = 0; s < kMaxSweeps; ++s)
    if (sweep(blocks, taken, face_normal, face_d, kSurfaceWarp, true) == 0 || !fit(blocks, face_normal, face_d)) break;
  if (blocks.size() == region.blocks.size()) return false;
  if (unsignedAngle(face_normal, region.normal) > max_turn) return false;
  normal = face_normal;
  d = face_d;
  return true;
}

bool BlockRegionGrower::seenEdgeOn(const std::vector<int>& blocks, const Eigen::Vector3d& normal) const
{
  // Only blocks whose rays meet the plane at an angle test it (a grazing block's centroid
  // lies on any plane along its ray): it is seen edge-on when they are too few to be a
  // region on their own, however many grazing blocks lie thin along it.
  double tested_points = 0.0;
  for (int b : blocks)
    if (!grazes(b, normal)) tested_points += grid_.block(b).count;
  return tested_points < params_.min_support;
}

bool BlockRegionGrower::centroidsBend(const std::vector<int>& blocks, const Eigen::Vector3d& normal, double d,
                                      double max_sag) const
{
  if (blocks.size() < 12) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int b : blocks) mean += info_[b].centroid;
  mean /= blocks.size();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  // Weighted least squares of the residual r = [1 u v u^2 uv v^2] c; the plane is the first three.
  Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  double chi2_plane = 0.0, rr = 0.0;
  for (int b : blocks)
  {
    const BlockInfo& i = info_[b];
    const double w = 1.0 / (i.centroid_variance + kMinBlockSigma * kMinBlockSigma / 64.0);
    const double x = (i.centroid - mean).dot(u), y = (i.centroid - mean).dot(v);
    const double r = normal.dot(i.centroid) + d;
    Eigen::Matrix<double, 6, 1> a;
    a << 1.0, x, y, x * x, x * y, y * y;
    normal_matrix += w * a * a.transpose();
    rhs += w * r * a;
    rr += w * r * r;
  }
  // The plane's own fit (first three terms) against the quadric's.
  const Eigen::Vector3d plane = normal_matrix.topLeftCorner<3, 3>().ldlt().solve(rhs.head<3>());
  chi2_plane = rr - rhs.head<3>().dot(plane);
  const Eigen::Matrix<double, 6, 1> quadric = normal_matrix.ldlt().solve(rhs);
  const double chi2_quadric = rr - rhs.dot(quadric);
  // Significant against the sensor's noise model; or against the region's own scatter about
  // the quadric (lack of fit, an F test), which sees a bend the model's conservative variance
  // hides (a cylinder's tangent strip 3.5 m away: chi^2 drop 9, F 42). That scatter knows
  // nothing of errors shared along the face, so a bend only it shows must be deeper than a real
  // face warps (kSurfaceWarp: cardboard bowing, a real sensor's low-order depth error).
  const double drop = chi2_plane - chi2_quadric, dof = static_cast<double>(blocks.size()) - 6.0;
  const bool beyond_model = drop > kChi2DropThreeDof;
  if (!beyond_model && !(drop / 3.0 > lackOfFitCritical(dof) * chi2_quadric / dof)) return false;
  const double sag_bar = beyond_model ? max_sag : std::max(max_sag, kSurfaceWarp);
  Eigen::Matrix2d hessian;
  hessian << 2.0 * quadric(3), quadric(4), quadric(4), 2.0 * quadric(5);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> curvatures;
  curvatures.computeDirect(hessian);
  for (int k = 0; k < 2; ++k)
  {
    const double curvature = std::abs(curvatures.eigenvalues()(k));
    if (curvature <= kMaxPlaneCurvature) continue;
    // Its sag over the region's width along that axis (sqrt(12 var) for an even spread).
    const Eigen::Vector3d axis = curvatures.eigenvectors()(0, k) * u + curvatures.eigenvectors()(1, k) * v;
    double variance = 0.0;
    for (int b : blocks) variance += std::pow(axis.dot(info_[b].centroid - mean), 2);
    variance /= blocks.size();
    if (curvature * 12.0 * variance / 8.0 > sag_bar) return true;
  }
  return false;
}

size_t BlockRegionGrower::continuingBlocks(const std::vector<int>& blocks, const Eigen::Vector3d& normal, double d,
                                          std::vector<int>& continuing, size_t* unoriented_on_plane,
                                          size_t* image_edge_sides) const
{
  if (unoriented_on_plane) *unoriented_on_plane = 0;
  if (image_edge_sides) *image_edge_sides = 0;
  const int bx_count = grid_.blocksX(), by_count = grid_.blocksY();
  around_.clear(info_.size());
  for (int b : blocks) around_.insert(b);
  continuing.clear();
  size_t boundary = 0;  // the blocks around it and its sides on the image's edge
  const double crease_cosine = std::cos(kCreaseAngle);
  for (int b : blocks)
  {
    // Beyond the image's edge the surface is unknown: it counts as a boundary.
    const int bx = b % bx_count, by = b / bx_count;
    const int edge_sides = (bx == 0) + (bx + 1 == bx_count) + (by == 0) + (by + 1 == by_count);
    boundary += edge_sides;
    if (image_edge_sides) *image_edge_sides += edge_sides;
    forEachNeighbour(b, bx_count, by_count, [&](int nb) {
      if (!around_.insertNew(nb)) return;
      ++boundary;
      const BlockInfo& i = info_[nb];
      if (!i.valid || !i.planar) return;
      if (std::abs(normal.dot(i.centroid) + d) > params_.merge_distance + 3.0 * std::sqrt(i.centroid_variance)) return;
      if (std::abs(i.normal.dot(normal)) < crease_cosine)
      {
        if (unoriented_on_plane && i.normal_tolerance >= M_PI / 2) ++*unoriented_on_plane;
        return;
      }
      continuing.push_back(nb);
    });
  }
  return boundary;
}

bool BlockRegionGrower::endsWhereItsSurfaceDoes(const std::vector<int>& blocks, const Eigen::Vector3d& normal,
                                                double d) const
{
  // Neither a block on its plane whose own normal is uninformative (its noise as thick as a good
  // part of its width), which cannot show a crease, nor the image's edge, beyond which the
  // surface is unknown, shows where the face ends.
  std::vector<int> continuing;
  size_t unoriented_on_plane = 0, image_edge_sides = 0;
  const size_t boundary = continuingBlocks(blocks, normal, d, continuing, &unoriented_on_plane, &image_edge_sides);
  return static_cast<double>(continuing.size() + unoriented_on_plane + image_edge_sides) <
         kMaxContinuingShareOfAFace * static_cast<double>(boundary);
}

bool BlockRegionGrower::continuesAndBends(const std::vector<int>& blocks, const Eigen::Vector3d& normal,
                                          double d) const
{
  std::vector<int> continuing;  // the blocks around it that continue its surface
  const size_t boundary = continuingBlocks(blocks, normal, d, continuing);
  if (2 * continuing.size() < boundary) return false;
  // Only a region that passes the share is copied: most (a floor's thousands of blocks) do not.
  std::vector<int> extended = blocks;
  extended.insert(extended.end(), continuing.begin(), continuing.end());
  return normalsTurn(extended, normal) || centroidsBend(extended, normal, d);
}

bool BlockRegionGrower::normalsTurn(const std::vector<int>& blocks, const Eigen::Vector3d& normal,
                                    double max_sag) const
{
  // Mean normal of each half (split across either in-plane axis), from the blocks whose own
  // normal is informative; their difference against its standard error from the scatter.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int informative = 0;
  for (int b : blocks)
    if (info_[b].normal_tolerance < M_PI / 2)
    {
      mean += info_[b].centroid;
      ++informative;
    }
  constexpr int kMinHalfBlocks = 3;
  if (informative < 2 * kMinHalfBlocks) return false;
  mean /= informative;
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  for (int b : blocks)
    if (info_[b].normal_tolerance < M_PI / 2)
    {
      const Eigen::Vector2d p((info_[b].centroid - mean).dot(u), (info_[b].centroid - mean).dot(v));
      spread += p * p.transpose();
    }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes;
  axes.computeDirect(spread);
  for (int a = 0; a < 2; ++a)
  {
    const Eigen::Vector3d axis = axes.eigenvectors()(0, a) * u + axes.eigenvectors()(1, a) * v;
    Eigen::Vector3d sum[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    Eigen::Vector3d where[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    double square[2] = {0.0, 0.0};
    int count[2] = {0, 0};
    for (int b : blocks)
    {
      const BlockInfo& i = info_[b];
      if (i.normal_tolerance >= M_PI / 2) continue;
      const int h = axis.dot(i.centroid - mean) >= 0.0 ? 1 : 0;
      const Eigen::Vector3d n = i.normal.dot(normal) >= 0.0 ? i.normal : Eigen::Vector3d(-i.normal);
      sum[h] += n;
      square[h] += n.squaredNorm();
      where[h] += i.centroid;
      ++count[h];
    }
    if (count[0] < kMinHalfBlocks || count[1] < kMinHalfBlocks) continue;
    double error_variance = 0.0;
    Eigen::Vector3d half_normal[2];
    for (int h = 0; h < 2; ++h)
    {
      const Eigen::Vector3d m = sum[h] / count[h];
      // Variance of the mean normal: the normals' own scatter over their number.
      error_variance += std::max(0.0, square[h] / count[h] - m.squaredNorm()) / (count[h] - 1);
      half_normal[h] = m.normalized();
      where[h] /= count[h];
    }
    const double tilt = std::acos(std::min(1.0, half_normal[0].dot(half_normal[1])));
    const double separation = (where[1] - where[0]).norm();
    // The halves' centres lie half the width apart, so the sag is tilt * separation / 2.
    if (tilt > 3.0 * std::sqrt(error_variance) && tilt > kMaxPlaneCurvature * separation &&
        tilt * separation / 2.0 > max_sag)
      return true;
  }
  return false;
}

bool BlockRegionGrower::fit(const std::vector<int>& blocks, Eigen::Vector3d& normal, double& d) const
{
  if (blocks.size() < 3) return false;
  const PointMoments sum = weightedCentroidMoments(info_, blocks);
  Eigen::Vector3d n;
  if (!sum.planeNormal(n)) return false;
  if (n.dot(normal) < 0.0) n = -n;
  normal = n;
  d = -n.dot(sum.mean());
  return true;
}

std::vector<int> interiorBlocks(const std::vector<int>& blocks, int bx_count, int by_count)
{
  std::vector<char> member(static_cast<size_t>(bx_count) * by_count, 0);
  for (int b : blocks) member[b] = 1;
  std::vector<int> interior;
  for (int b : blocks)
  {
    int inside = 0;
    forEachNeighbour(b, bx_count, by_count, [&](int nb) { inside += member[nb]; });
    if (inside == 4) interior.push_back(b);
  }
  return interior;
}

bool BlockRegionGrower::fitInterior(const std::vector<int>& blocks, Eigen::Vector3d& normal, double& d) const
{
  const std::vector<int> interior = interiorBlocks(blocks, grid_.blocksX(), grid_.blocksY());
  if (interior.size() >= kMinInteriorBlocks && fit(interior, normal, d)) return true;
  return fit(blocks, normal, d);
}

std::vector<std::vector<int>> BlockRegionGrower::seedComponents(const Eigen::Vector3d& normal, double d,
                                                                const std::vector<char>& taken)
{
  std::vector<int> agreeing;
  for (size_t b = 0; b < info_.size(); ++b)
    if (!taken[b] && accepts(static_cast<int>(b), normal, d)) agreeing.push_back(static_cast<int>(b));
  std::vector<std::vector<int>> components;
  components_.forEach(agreeing, grid_.blocksX(), grid_.blocksY(),
                      [&](const std::vector<int>& component) { components.push_back(component); });
  std::sort(components.begin(), components.end(),
            [](const std::vector<int>& a, const std::vector<int>& b) { return a.size() > b.size(); });
  return components;
}

PlaneRegion BlockRegionGrower::grow(const std::vector<int>& seed, const Eigen::Vector3d& normal, double d,
                                    const std::vector<char>& taken)
{
  PlaneRegion region;
  region.normal = normal;
  region.d = d;
  region.blocks = seed;
  fit(region.blocks, region.normal, region.d);
  // Each sweep grows from the whole region against the last fit; a better plane may admit
  // blocks the first guess refused (and keep those it no longer would: they were on it).
  constexpr int kMaxSweeps = 4;
  for (int s = 0; s < kMaxSweeps; ++s)
  {
    const bool grew = sweep(region.blocks, taken, region.normal, region.d) > 0;
    fit(region.blocks, region.normal, region.d);
    if (!grew) break;
  }
  // Blocks that joined at the plane's first guess but lie beyond two sigmas of the interior's
  // plane (edges where a riser meets a tread) would tilt it: the fit is made again without
  // them, over all blocks kept (the curvature tests need the rim a tangent plane would miss).
  fitInterior(region.blocks, region.normal, region.d);
  for (int pass = 0; pass < 2; ++pass)
  {
    std::vector<int> inliers, outliers;
    for (int b : region.blocks)
      (std::abs(region.normal.dot(info_[b].centroid) + region.d) <= (2.0 / 3.0) * info_[b].region_residual ? inliers
                                                                                                              : outliers)
          .push_back(b);
    if (outliers.empty() || !fit(inliers, region.normal, region.d)) break;
    region.blocks.swap(inliers);
    region.trimmed.insert(region.trimmed.end(), outliers.begin(), outliers.end());
  }
  for (int b : region.blocks) region.points += grid_.block(b).count;
  return region;
}

}  // namespace hough_plane_detector
