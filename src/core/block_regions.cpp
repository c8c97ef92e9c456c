#include "hough_plane_detector/core/block_regions.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace hough_plane_detector
{

namespace
{
constexpr double kMinBlockSigma = 0.001;   // m: no block is judged flatter than a millimetre
constexpr double kMaxNormalTolerance = 1.0;  // rad: a block's normal is never trusted less than this
constexpr double kMaxThicknessRatio = 0.25;  // noise variance over in-plane spread: beyond, no normal
// Depth error that does not average out over a block (calibration residue of structured
// light, surfaces a little off flat), per squared metre of depth: 1.5 mm at 1 m.
constexpr double kSystematicPerSquareMetre = 0.0015;
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

PointMoments weightedCentroidMoments(const NormalEstimator& grid, const std::vector<BlockInfo>& info,
                                     const std::vector<int>& blocks)
{
  const int bx_count = grid.blocksX();
  PointMoments sum;
  for (int b : blocks)
  {
    PointMoments m = centroidMoments(grid.block(b % bx_count, b / bx_count));
    m.scale(info[b].fit_weight);
    sum.add(m);
  }
  return sum;
}

void describeBlocks(const NormalEstimator& grid, const DetectorParams& params, std::vector<BlockInfo>& info)
{
  const int bx_count = grid.blocksX(), count = grid.blocksX() * grid.blocksY();
  info.assign(count, BlockInfo());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  const bool noise_aware = params.sensor_noise > 0.0;
  for (int b = 0; b < count; ++b)
  {
    const PointMoments& block = grid.block(b % bx_count, b / bx_count);
    BlockInfo& i = info[b];
    i.valid = block.count >= 3;
    if (!i.valid) continue;
    i.centroid = block.mean();
    i.covariance = block.covariance();
    const double sigma = sensorDepthSigma(i.centroid.z(), params.sensor_noise);
    const double step = noise_aware ? quantizationStep(i.centroid.z()) : 0.0;
    // Quantization moves a block as a whole, so it does not average out over the block.
    i.centroid_variance = sigma * sigma / block.count + step * step / 12.0;
    // Around a fitted plane a centroid may stray by its noise and 1 cm of sensor warp.
    i.tight_residual = noise_aware ? 0.01 + 3.0 * std::sqrt(i.centroid_variance) : params.support_distance;
    i.thickness_limit = noise_aware ? 6.25 * sigma * sigma + 1e-4 : 0.25 * params.support_distance * params.support_distance;
    i.fit_weight = 1.0 / (sigma * sigma + 1e-6);
    const double systematic = kSystematicPerSquareMetre * i.centroid.z() * i.centroid.z();
    const double block_sigma = std::max(kMinBlockSigma, sigma);
    i.region_residual = 3.0 * std::sqrt(block_sigma * block_sigma / block.count + step * step / 12.0 + systematic * systematic);
    solver.computeDirect(i.covariance);
    i.normal = solver.eigenvectors().col(0);
    if (i.normal.dot(i.centroid) > 0.0) i.normal = -i.normal;
    // Flat: thinner along its normal than three sigmas of the sensor's noise (an edge or a
    // depth jump inside the block is thicker). Its normal is then good to sigma over its
    // narrower half-width, per point.
    const Eigen::Vector3d eigenvalues = solver.eigenvalues().cwiseMax(0.0);
    i.planar = block.count >= 8 && (noise_aware ? eigenvalues(0) <= 9.0 * block_sigma * block_sigma : eigenvalues(0) <= i.thickness_limit);
    // Where the block is as thick as half its width (noise far from a Kinect) its smallest
    // eigenvector may lie in the surface: such a block is judged by its centroid alone. Both
    // come from the block's own scatter, so a sensor quieter than the model is used as it is.
    const double normal_sigma = std::sqrt(eigenvalues(0) / (std::max(1e-12, eigenvalues(1)) * block.count));
    const bool normal_informative = eigenvalues(0) < kMaxThicknessRatio * eigenvalues(1);
    i.normal_tolerance = normal_informative ? std::min(kMaxNormalTolerance, std::max(params.support_angle, 3.0 * normal_sigma))
                                            : M_PI / 2;
  }
}

BlockRegionGrower::BlockRegionGrower(const NormalEstimator& grid, const std::vector<BlockInfo>& info,
                                     const DetectorParams& params)
  : grid_(grid), info_(info), params_(params), mark_(info.size(), 0)
{
}

bool BlockRegionGrower::accepts(int block, const Eigen::Vector3d& normal, double d) const
{
  const BlockInfo& i = info_[block];
  if (!i.planar) return false;
  if (std::abs(i.normal.dot(normal)) < std::cos(i.normal_tolerance)) return false;
  return std::abs(normal.dot(i.centroid) + d) <= std::min(params_.support_distance, i.region_residual);
}

bool BlockRegionGrower::fit(const std::vector<int>& blocks, Eigen::Vector3d& normal, double& d) const
{
  if (blocks.size() < 3) return false;
  const PointMoments sum = weightedCentroidMoments(grid_, info_, blocks);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(sum.covariance());
  // Centroids along one line (a row of blocks) fix no plane.
  if (!(solver.eigenvalues()(1) > 1e-3 * solver.eigenvalues()(2))) return false;
  Eigen::Vector3d n = solver.eigenvectors().col(0).normalized();
  if (n.dot(normal) < 0.0) n = -n;
  normal = n;
  d = -n.dot(sum.mean());
  return true;
}

std::vector<std::vector<int>> BlockRegionGrower::seedComponents(const Eigen::Vector3d& normal, double d,
                                                                const std::vector<char>& taken)
{
  const int bx_count = grid_.blocksX(), by_count = grid_.blocksY();
  ++generation_;
  const int member = generation_;
  for (size_t b = 0; b < info_.size(); ++b)
    if (!taken[b] && accepts(static_cast<int>(b), normal, d)) mark_[b] = member;
  ++generation_;  // visited
  std::vector<std::vector<int>> components;
  for (size_t seed = 0; seed < info_.size(); ++seed)
  {
    if (mark_[seed] != member) continue;
    std::vector<int> component(1, static_cast<int>(seed));
    mark_[seed] = generation_;
    for (size_t head = 0; head < component.size(); ++head)
      forEachNeighbour(component[head], bx_count, by_count, [&](int nb) {
        if (mark_[nb] != member) return;
        mark_[nb] = generation_;
        component.push_back(nb);
      });
    components.push_back(std::move(component));
  }
  std::sort(components.begin(), components.end(),
            [](const std::vector<int>& a, const std::vector<int>& b) { return a.size() > b.size(); });
  return components;
}

PlaneRegion BlockRegionGrower::grow(const std::vector<int>& seed, const Eigen::Vector3d& normal, double d,
                                    const std::vector<char>& taken)
{
  const int bx_count = grid_.blocksX(), by_count = grid_.blocksY();
  PlaneRegion region;
  region.normal = normal;
  region.d = d;
  region.blocks = seed;
  fit(region.blocks, region.normal, region.d);
  // Each sweep grows from the whole region against the last fit; a better plane may admit
  // blocks the first guess refused (and keep those it no longer would: they were on it).
  constexpr int kMaxSweeps = 4;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep)
  {
    ++generation_;
    for (int b : region.blocks) mark_[b] = generation_;
    const size_t before = region.blocks.size();
    for (size_t head = 0; head < region.blocks.size(); ++head)
      forEachNeighbour(region.blocks[head], bx_count, by_count, [&](int nb) {
        if (mark_[nb] == generation_ || taken[nb]) return;
        mark_[nb] = generation_;
        if (accepts(nb, region.normal, region.d)) region.blocks.push_back(nb);
      });
    const bool grew = region.blocks.size() > before;
    fit(region.blocks, region.normal, region.d);
    if (!grew) break;
  }
  for (int b : region.blocks) region.points += grid_.block(b % bx_count, b / bx_count).count;
  return region;
}

}  // namespace hough_plane_detector
