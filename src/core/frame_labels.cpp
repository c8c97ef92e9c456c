#include "hough_plane_detector/core/frame_labels.h"

#include <cmath>
#include <unordered_map>

#include "hough_plane_detector/core/plane_geometry.h"

namespace hough_plane_detector
{

namespace
{
constexpr double kPixelBandSigmas = 3.0;  // a pixel on a plane lies within 3 sigma of its depth noise
// Index of the plane a window lies on, or -1; sign-invariant.
int bestPlaneFor(const WindowSample& sample, const std::vector<DetectedPlane>& planes, const DetectorParams& params)
{
  const double cos_limit = std::cos(params.support_angle);
  int best = -1;
  double best_distance = params.support_distance;
  for (size_t i = 0; i < planes.size(); ++i)
  {
    if (std::abs(sample.normal.dot(planes[i].normal)) < cos_limit) continue;
    const double distance = std::abs(planes[i].normal.dot(sample.centroid) + planes[i].d);
    if (distance <= best_distance)
    {
      best_distance = distance;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// Each accepted region labels its blocks with the map plane closest to it (within the merge
// tolerances); a block goes to the first region that has it.
void labelRegionBlocks(const DetectorParams& params, FrameData& frame, const std::vector<FramePlane>& frame_planes,
                       const std::vector<DetectedPlane>& planes, FrameLabels& labels)
{
  frame.block_claim.assign(labels.blocks.size(), 0);
  for (const FramePlane& region : frame_planes)
  {
    int best = -1;
    double best_cost = 2.0;
    for (size_t p = 0; p < planes.size(); ++p)
    {
      const double sign = planes[p].normal.dot(region.normal) >= 0.0 ? 1.0 : -1.0;
      const double cost = unsignedAngle(planes[p].normal, region.normal) / (params.merge_angle + 1e-9) +
                          std::abs(planes[p].d - sign * region.d) / (params.merge_distance + 1e-9);
      if (cost < best_cost)
      {
        best_cost = cost;
        best = static_cast<int>(p);
      }
    }
    if (best < 0) continue;
    for (int b : region.blocks)
    {
      if (frame.block_claim[b]) continue;
      frame.block_claim[b] = 1;
      labels.blocks[b] = planes[best].id;
      labels.support[best] += static_cast<int>(frame.points(b));
    }
  }
}
}  // namespace

void labelFrame(const DetectorParams& params, FrameData& frame, FramePlaneFitter& fitter,
                const std::vector<FramePlane>& frame_planes, const std::vector<DetectedPlane>& planes,
                FrameLabels& labels)
{
  labels.samples.assign(frame.samples.size(), -1);
  std::vector<std::vector<int>> plane_windows(planes.size());
  for (size_t s = 0; s < frame.samples.size(); ++s)
  {
    const int best = bestPlaneFor(frame.samples[s], planes, params);
    if (best < 0) continue;
    plane_windows[best].push_back(static_cast<int>(s));
    labels.samples[s] = planes[best].id;
  }
  labels.blocks.assign(static_cast<size_t>(frame.blocksX()) * frame.blocksY(), -1);
  labels.support.assign(planes.size(), 0);
  frame.block_claim.clear();  // the map's planes are distinct: each takes its own windows' blocks
  if (params.region_growing) labelRegionBlocks(params, frame, frame_planes, planes, labels);
  std::vector<int> blocks;
  for (size_t p = 0; p < planes.size(); ++p)
  {
    if (labels.support[p] > 0) continue;
    const PointMoments moments = fitter.collectPlaneBlocks(planes[p].normal, planes[p].d, plane_windows[p], blocks);
    labels.support[p] = static_cast<int>(moments.count);
    for (int b : blocks) labels.blocks[b] = planes[p].id;
  }
}

void labelPixels(const CloudView& cloud, const FrameData& frame, const std::vector<int>& block_labels,
                 const std::vector<DetectedPlane>& planes, const DetectorParams& params, std::vector<int>& labels)
{
  labels.assign(cloud.size(), -1);
  const int s = blockSize(params.normal_window, params.normal_stride), bx_count = frame.blocksX(),
            by_count = frame.blocksY();
  if (block_labels.empty() || cloud.width / s != bx_count || cloud.height / s != by_count) return;
  std::unordered_map<int, std::pair<Eigen::Vector3d, double>> camera_planes;
  for (const DetectedPlane& plane : planes)
    camera_planes[plane.id] = {frame.normalInCamera(plane.normal), frame.dInCamera(plane.normal, plane.d)};
  // Each pixel of block b with a return: its point and its label.
  auto forEachPoint = [&](int b, const auto& visit) {
    const int bx = b % bx_count, by = b / bx_count;
    for (int v = by * s; v < (by + 1) * s; ++v)
      for (int u = bx * s; u < (bx + 1) * s; ++u)
      {
        float x, y, z;
        cloud.point(u, v, x, y, z);
        if (std::isfinite(x + y + z)) visit(Eigen::Vector3d(x, y, z), labels[static_cast<size_t>(v) * cloud.width + u]);
      }
  };
  for (size_t b = 0; b < block_labels.size(); ++b)
  {
    if (block_labels[b] < 0) continue;
    const auto& plane = camera_planes[block_labels[b]];
    forEachPoint(static_cast<int>(b), [&](const Eigen::Vector3d& p, int& label) {
      if (std::abs(plane.first.dot(p) + plane.second) <= params.support_distance) label = block_labels[b];
    });
  }
  // A region leaves out blocks whose centroids its noise tests put off the plane (a real
  // sensor's depth errors are correlated over many pixels), yet their points lie on it: from its
  // blocks a plane's label spreads to the unlabelled blocks around them, to each pixel whose depth
  // lies within kPixelBandSigmas of the sensor's noise of where the plane meets its ray, and on
  // from a block where most points lie so. A surface off the plane (an object on a table) stops it.
  std::vector<int> spread(block_labels), refused_for(block_labels.size(), -1);  // a block is tried once per plane
  std::vector<int> queue;
  for (size_t b = 0; b < spread.size(); ++b)
    if (spread[b] >= 0) queue.push_back(static_cast<int>(b));
  for (size_t next = 0; next < queue.size(); ++next)
  {
    const int from = queue[next], id = spread[from];
    const auto& plane = camera_planes[id];
    const int fx = from % bx_count, fy = from / bx_count;
    const int neighbours[4][2] = {{fx - 1, fy}, {fx + 1, fy}, {fx, fy - 1}, {fx, fy + 1}};
    for (const auto& n : neighbours)
    {
      if (n[0] < 0 || n[0] >= bx_count || n[1] < 0 || n[1] >= by_count) continue;
      const int b = n[1] * bx_count + n[0];
      if (spread[b] >= 0 || refused_for[b] == id || frame.points(b) <= 0) continue;
      int valid = 0, on_plane = 0;
      forEachPoint(b, [&](const Eigen::Vector3d& p, int& label) {
        ++valid;
        // |n . p + d| = |n . p| / z * |z - expected depth|: the test in depth, as measured.
        const double along_normal = plane.first.dot(p);
        const double band = kPixelBandSigmas * frame.noise.sigma(p.z()) * std::abs(along_normal) / p.z();
        if (std::abs(along_normal + plane.second) > band) return;
        ++on_plane;
        if (label < 0) label = id;
      });
      if (valid > 0 && 2 * on_plane > valid)
      {
        spread[b] = id;
        queue.push_back(b);
      }
      else
      {
        refused_for[b] = id;
      }
    }
  }
}

}  // namespace hough_plane_detector
