#include "hough_plane_detector/core/normal_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <Eigen/Eigenvalues>

#ifdef __SSE2__
#include <xmmintrin.h>
#endif

#include "hough_plane_detector/core/symmetric_eigen.h"

namespace hough_plane_detector
{

Eigen::Matrix3d PointMoments::covariance() const
{
  const Eigen::Vector3d m = mean();
  Eigen::Matrix3d c;
  c << xx / count - m.x() * m.x(), xy / count - m.x() * m.y(), xz / count - m.x() * m.z(),
       0, yy / count - m.y() * m.y(), yz / count - m.y() * m.z(),
       0, 0, zz / count - m.z() * m.z();
  c(1, 0) = c(0, 1);
  c(2, 0) = c(0, 2);
  c(2, 1) = c(1, 2);
  return c;
}

bool PointMoments::planeNormal(Eigen::Vector3d& normal) const
{
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance());
  if (!(solver.eigenvalues()(1) > 1e-3 * solver.eigenvalues()(2))) return false;
  normal = solver.eigenvectors().col(0).normalized();
  return true;
}

PointMoments PointMoments::transformed(const Eigen::Isometry3d& transform) const
{
  // sum (R p + t)(R p + t)^T = R S R^T + R s t^T + t s^T R^T + n t t^T
  const Eigen::Matrix3d r = transform.linear();
  const Eigen::Vector3d t = transform.translation();
  Eigen::Matrix3d s;
  s << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  const Eigen::Vector3d rs = r * sum;
  const Eigen::Matrix3d out = r * s * r.transpose() + rs * t.transpose() + t * rs.transpose() + count * t * t.transpose();
  PointMoments m;
  m.count = count;
  m.sum = rs + count * t;
  m.xx = out(0, 0); m.xy = out(0, 1); m.xz = out(0, 2); m.yy = out(1, 1); m.yz = out(1, 2); m.zz = out(2, 2);
  return m;
}

int blockSize(int /*window: a multiple of the stride*/, int stride)
{
  // The largest divisor of the stride (so also of the window) that is at most 8.
  for (int b = std::min(8, stride); b > 1; --b)
    if (stride % b == 0) return b;
  return 1;
}

namespace
{
// Squared thickness over squared width (smallest over middle eigenvalue) above which a window's
// normal is re-measured over a wider window: thickness more than half the width.
constexpr double kMaxThicknessRatio = 0.25;
}  // namespace

void NormalEstimator::compute(const CloudView& cloud, const Eigen::Isometry3d& camera_to_world,
                              const NormalEstimatorConfig& config, std::vector<WindowSample>& samples,
                              ThreadTeam& team)
{
  samples.clear();
  valid_windows_ = 0;
  // Blocks of at most 8 x 8 pixels carry the moments (the planarity tests downstream work on
  // them); windows are k x k blocks placed every `step` blocks.
  const int s = blockSize(config.window, config.stride);
  blocks_x_ = cloud.width / s;
  blocks_y_ = cloud.height / s;
  blocks_.assign(static_cast<size_t>(blocks_x_) * blocks_y_, PointMoments());
  if (blocks_x_ == 0 || blocks_y_ == 0) return;
  accumulateBlocks(cloud, s, team);

  const int k = config.window / s;
  const int step = config.stride / s;
  use_integral_ = k > 1 || config.max_window_scale > 1;  // wider windows read it too
  if (use_integral_) buildIntegral();

  const double min_count = config.min_valid_fraction * config.window * config.window;
  const Eigen::Matrix3d rotation = camera_to_world.linear();
  const Eigen::Vector3d translation = camera_to_world.translation();
  const int window_rows = blocks_y_ >= k ? (blocks_y_ - k) / step + 1 : 0;
  // Each row of windows keeps its own samples; joined in row order they come out the same
  // whichever thread measured which row.
  std::vector<std::vector<WindowSample>> row_samples(window_rows);
  std::vector<int> row_valid(window_rows, 0);
  team.forEach(window_rows, [&](int row, int) {
    const int wy = row * step;
    // Filled locally and stored once: neighbouring rows' entries share cache lines.
    std::vector<WindowSample> measured;
    int valid = 0;
    for (int wx = 0; wx + k <= blocks_x_; wx += step)
    {
      const double count = windowMoments(wx, wy, wx + k, wy + k).count;
      if (count < min_count) continue;
      ++valid;
      Eigen::Vector3d normal, mean;
      if (!measureWindow(wx, wy, k, config, normal, mean)) continue;
      if (normal.dot(mean) > 0.0) normal = -normal;  // toward the sensor at the origin
      WindowSample sample;
      sample.normal = rotation * normal;
      sample.centroid = rotation * mean + translation;
      sample.d = -sample.normal.dot(sample.centroid);
      sample.count = static_cast<int>(count);  // votes count the window's own points
      sample.window_x = wx;
      sample.window_y = wy;
      measured.push_back(sample);
    }
    row_valid[row] = valid;
    row_samples[row] = std::move(measured);
  });
  for (int row = 0; row < window_rows; ++row)
  {
    valid_windows_ += row_valid[row];
    samples.insert(samples.end(), row_samples[row].begin(), row_samples[row].end());
  }
}

namespace
{
// Per block, float sums relative to the block's first valid point keep full precision (sums of
// squares of metres in float would swamp millimetre noise); doubles after that.
struct BlockAccumulator
{
  float rx, ry, rz;
  float n;
  float sx, sy, sz, xx, xy, xz, yy, yz, zz;
};

// Each block of row `by` starts empty with its first valid point as reference (found before the
// main pass, so the per-point loop has no data-dependent branch).
void startBlockRow(const CloudView& cloud, int by, int s, std::vector<BlockAccumulator>& row_blocks)
{
  for (size_t bx = 0; bx < row_blocks.size(); ++bx)
  {
    BlockAccumulator& b = row_blocks[bx];
    b = BlockAccumulator{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    bool found = false;
    for (int v = by * s; v < (by + 1) * s && !found; ++v)
      for (int u = static_cast<int>(bx) * s; u < static_cast<int>(bx + 1) * s && !found; ++u)
      {
        float x, y, z;
        cloud.point(u, v, x, y, z);
        if (std::isfinite(x + y + z))
        {
          b.rx = x; b.ry = y; b.rz = z;
          found = true;
        }
      }
  }
}

// Adds pixel row v to the blocks it crosses.
void accumulatePixelRow(const CloudView& cloud, int v, int s, std::vector<BlockAccumulator>& row_blocks)
{
  const uint8_t* row = cloud.data + static_cast<size_t>(v) * cloud.row_step;
  for (size_t bx = 0; bx < row_blocks.size(); ++bx)
  {
    BlockAccumulator& b = row_blocks[bx];
    const uint8_t* p = row + bx * s * cloud.point_step;
    float n = 0, sx = 0, sy = 0, sz = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
    for (int i = 0; i < s; ++i, p += cloud.point_step)
    {
      float x, y, z;
      std::memcpy(&x, p + cloud.x_offset, sizeof(float));
      std::memcpy(&y, p + cloud.y_offset, sizeof(float));
      std::memcpy(&z, p + cloud.z_offset, sizeof(float));
      const bool valid = std::isfinite(x + y + z);  // NaN or Inf in any coordinate
      const float qx = valid ? x - b.rx : 0.0f, qy = valid ? y - b.ry : 0.0f, qz = valid ? z - b.rz : 0.0f;
      n += valid ? 1.0f : 0.0f;
      sx += qx; sy += qy; sz += qz;
      xx += qx * qx; xy += qx * qy; xz += qx * qz;
      yy += qy * qy; yz += qy * qz; zz += qz * qz;
    }
    b.n += n;
    b.sx += sx; b.sy += sy; b.sz += sz;
    b.xx += xx; b.xy += xy; b.xz += xz; b.yy += yy; b.yz += yz; b.zz += zz;
  }
}

#ifdef __SSE2__
// Where x, y, z are consecutive floats (PCL's XYZ, XYZRGB, packed or padded) and the block's
// width is a multiple of four, four pixels at a time: each load reads the 4 bytes after z (the
// point's padding or the next point's x), so the cloud's last row goes this way only where the
// points are padded.
bool fourPixelsFit(const CloudView& cloud, int by, int s)
{
  return s % 4 == 0 && cloud.y_offset == cloud.x_offset + 4 && cloud.z_offset == cloud.x_offset + 8 &&
         (cloud.x_offset + 16 <= cloud.point_step || (by + 1) * s < cloud.height);
}

float laneSum(__m128 v)
{
  const __m128 pairs = _mm_add_ps(v, _mm_movehl_ps(v, v));
  return _mm_cvtss_f32(_mm_add_ss(pairs, _mm_shuffle_ps(pairs, pairs, 0x55)));
}

// One block's sums as accumulatePixelRow makes them, each lane summing every fourth pixel (so
// they differ from it in the last bits), at under half its instructions per pixel.
void accumulateBlockFourPixels(const CloudView& cloud, int bx, int by, int s, BlockAccumulator& b)
{
  const __m128 rx = _mm_set1_ps(b.rx), ry = _mm_set1_ps(b.ry), rz = _mm_set1_ps(b.rz);
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  __m128 n = zero, sx = zero, sy = zero, sz = zero, xx = zero, xy = zero, xz = zero, yy = zero, yz = zero, zz = zero;
  const size_t step = cloud.point_step;
  for (int v = by * s; v < (by + 1) * s; ++v)
  {
    const uint8_t* p = cloud.data + static_cast<size_t>(v) * cloud.row_step + static_cast<size_t>(bx) * s * step +
                       cloud.x_offset;
    for (int i = 0; i < s; i += 4, p += 4 * step)
    {
      __m128 x = _mm_loadu_ps(reinterpret_cast<const float*>(p));
      __m128 y = _mm_loadu_ps(reinterpret_cast<const float*>(p + step));
      __m128 z = _mm_loadu_ps(reinterpret_cast<const float*>(p + 2 * step));
      __m128 rest = _mm_loadu_ps(reinterpret_cast<const float*>(p + 3 * step));
      _MM_TRANSPOSE4_PS(x, y, z, rest);
      const __m128 sum = _mm_add_ps(_mm_add_ps(x, y), z);
      const __m128 valid = _mm_cmpeq_ps(_mm_sub_ps(sum, sum), zero);  // NaN or Inf in any coordinate fails
      const __m128 qx = _mm_and_ps(_mm_sub_ps(x, rx), valid);
      const __m128 qy = _mm_and_ps(_mm_sub_ps(y, ry), valid);
      const __m128 qz = _mm_and_ps(_mm_sub_ps(z, rz), valid);
      n = _mm_add_ps(n, _mm_and_ps(one, valid));
      sx = _mm_add_ps(sx, qx); sy = _mm_add_ps(sy, qy); sz = _mm_add_ps(sz, qz);
      xx = _mm_add_ps(xx, _mm_mul_ps(qx, qx)); xy = _mm_add_ps(xy, _mm_mul_ps(qx, qy));
      xz = _mm_add_ps(xz, _mm_mul_ps(qx, qz)); yy = _mm_add_ps(yy, _mm_mul_ps(qy, qy));
      yz = _mm_add_ps(yz, _mm_mul_ps(qy, qz)); zz = _mm_add_ps(zz, _mm_mul_ps(qz, qz));
    }
  }
  b.n = laneSum(n);
  b.sx = laneSum(sx); b.sy = laneSum(sy); b.sz = laneSum(sz);
  b.xx = laneSum(xx); b.xy = laneSum(xy); b.xz = laneSum(xz); b.yy = laneSum(yy); b.yz = laneSum(yz); b.zz = laneSum(zz);
}
#endif

// The block's moments about the origin: S = Q + r q^T + q r^T + n r r^T for relative sums Q, q.
void toMoments(const BlockAccumulator& b, PointMoments& m)
{
  const double n = b.n, rx = b.rx, ry = b.ry, rz = b.rz;
  m.count = n;
  m.sum = Eigen::Vector3d(b.sx + n * rx, b.sy + n * ry, b.sz + n * rz);
  m.xx = b.xx + 2.0 * rx * b.sx + n * rx * rx;
  m.yy = b.yy + 2.0 * ry * b.sy + n * ry * ry;
  m.zz = b.zz + 2.0 * rz * b.sz + n * rz * rz;
  m.xy = b.xy + rx * b.sy + ry * b.sx + n * rx * ry;
  m.xz = b.xz + rx * b.sz + rz * b.sx + n * rx * rz;
  m.yz = b.yz + ry * b.sz + rz * b.sy + n * ry * rz;
}
}  // namespace

void NormalEstimator::accumulateBlocks(const CloudView& cloud, int s, ThreadTeam& team)
{
  // Block rows are independent; each thread sums into its own row buffer.
  std::vector<std::vector<BlockAccumulator>> row_blocks(team.size(), std::vector<BlockAccumulator>(blocks_x_));
  team.forEach(blocks_y_, [&](int by, int member) {
    std::vector<BlockAccumulator>& row = row_blocks[member];
    startBlockRow(cloud, by, s, row);
#ifdef __SSE2__
    if (fourPixelsFit(cloud, by, s))
      for (int bx = 0; bx < blocks_x_; ++bx) accumulateBlockFourPixels(cloud, bx, by, s, row[bx]);
    else
#endif
      for (int v = by * s; v < (by + 1) * s; ++v) accumulatePixelRow(cloud, v, s, row);
    for (int bx = 0; bx < blocks_x_; ++bx)
      if (row[bx].n > 0.0f) toMoments(row[bx], blocks_[static_cast<size_t>(by) * blocks_x_ + bx]);
  });
}

void NormalEstimator::buildIntegral()
{
  // Summed-area table over blocks: a window of k x k blocks costs four look-ups.
  const int ix = blocks_x_ + 1;
  integral_.assign(static_cast<size_t>(ix) * (blocks_y_ + 1), PointMoments());
  for (int by = 0; by < blocks_y_; ++by)
  {
    PointMoments row_sum;
    for (int bx = 0; bx < blocks_x_; ++bx)
    {
      row_sum.add(blocks_[static_cast<size_t>(by) * blocks_x_ + bx]);
      PointMoments& cell = integral_[static_cast<size_t>(by + 1) * ix + bx + 1];
      cell = integral_[static_cast<size_t>(by) * ix + bx + 1];
      cell.add(row_sum);
    }
  }
}

PointMoments NormalEstimator::windowMoments(int x0, int y0, int x1, int y1) const
{
  x0 = std::max(0, x0);
  y0 = std::max(0, y0);
  x1 = std::min(blocks_x_, x1);
  y1 = std::min(blocks_y_, y1);
  if (!use_integral_) return blocks_[static_cast<size_t>(y0) * blocks_x_ + x0];
  const int ix = blocks_x_ + 1;
  PointMoments m = integral_[static_cast<size_t>(y1) * ix + x1];
  m.subtract(integral_[static_cast<size_t>(y0) * ix + x1]);
  m.subtract(integral_[static_cast<size_t>(y1) * ix + x0]);
  m.add(integral_[static_cast<size_t>(y0) * ix + x0]);
  return m;
}

bool NormalEstimator::measureWindow(int wx, int wy, int k, const NormalEstimatorConfig& config,
                                    Eigen::Vector3d& normal, Eigen::Vector3d& mean) const
{
  // Far from a Kinect a window can be as thick (noise) as it is wide, and its normal is then
  // mostly noise: measure it again over a window twice, then four times, as wide around it.
  // The widest planar measurement wins; a wider window that crosses an edge keeps the last.
  bool planar = false;
  for (int scale = 1; scale <= config.max_window_scale; scale *= 2)
  {
    const int x0 = wx - k * (scale - 1) / 2, y0 = wy - k * (scale - 1) / 2;
    const PointMoments m = windowMoments(x0, y0, x0 + k * scale, y0 + k * scale);
    // Depth noise moves points along their rays, which tilts a plain covariance normal
    // toward the ray on oblique surfaces (0.1 rad on a wall 2.5 m away seen at 45 deg at
    // C = 1): the noise covariance along the ray is taken out, no more of it than the
    // window's own thickness shows (so a window less noisy than the model is not over-corrected).
    const Eigen::Vector3d centre = m.mean();
    const double sigma = config.noise.sigma(centre.z());
    const Eigen::Vector3d ray = centre / centre.z();  // a depth error e moves a point by e * ray
    const Eigen::Matrix3d covariance = m.covariance();
    SmallestEigenpair eigen = smallestEigenpair(covariance);
    const double ray_along_normal = ray.dot(eigen.vector);
    const double noise_variance = std::min(sigma * sigma, std::max(0.0, eigen.values(0)) /
                                                               std::max(1e-9, ray_along_normal * ray_along_normal));
    if (noise_variance > 0.0) eigen = smallestEigenpair(covariance - noise_variance * ray * ray.transpose());
    const Eigen::Vector3d eigenvalues = eigen.values;
    const double trace = eigenvalues.sum();
    if (!(trace > 0.0)) break;
    // Planar when flat relative to its size, or no rougher than the sensor's noise at that
    // depth (far windows of a Kinect are never flat in the first sense).
    const double noise = 3.0 * sigma;
    if (eigenvalues(0) > config.max_curvature * trace && eigenvalues(0) > noise * noise) continue;
    planar = true;
    normal = eigen.vector;
    mean = centre;
    if (eigenvalues(0) <= kMaxThicknessRatio * eigenvalues(1)) break;
  }
  return planar;
}

}  // namespace hough_plane_detector
