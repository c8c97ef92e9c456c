// The per-frame stages on rendered frames: planarity tests, the fits from Hough peaks
// (windows and block regions) and the parallel-plane search.
#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/core/frame_planes.h"
#include "hough_plane_detector/core/parallel_planes.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

namespace
{
// A floor, a wall 3.5 m ahead, a step 20 cm high and 30 cm deep before it, a pillar.
Scene stepScene()
{
  Scene scene;
  scene.addRectangle(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 3, 3, "floor");
  scene.addRectangle(Eigen::Vector3d(3.5, 0, 1.4), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 3, 1.4, "wall");
  scene.addBox(Eigen::Vector3d(2.0, 0.3, 0.1), Eigen::Vector3d(0.15, 0.6, 0.1), 0.0, "step");
  scene.cylinders.push_back({Eigen::Vector3d(1.6, -0.7, 0), 0.25, 2.0});
  return scene;
}

struct Frame
{
  DetectorParams params;
  HoughParameterization param{params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance, 8};
  SceneRenderer renderer;
  RenderedFrame rendered;
  FrameData frame;
  PlanarityTests tests{params, frame};

  explicit Frame(const Scene& scene = stepScene(),
                 const Eigen::Isometry3d& pose = lookAt(Eigen::Vector3d(0, 0, 1.2), Eigen::Vector3d(3, 0, 0.4)))
    : renderer(scene)
  {
    KinectNoise noise;
    rendered = renderer.render(pose, noise, 7);
    frame.measure(rendered.view(), rendered.camera_to_world, params, DepthNoiseModel(params.sensor_model, 1.0, 0.0));
    frame.block_claim.assign(frame.blocks.size(), 0);
  }
  int truePlane(const std::string& name) const
  {
    for (size_t i = 0; i < renderer.truePlanes().size(); ++i)
      if (renderer.truePlanes()[i].name == name) return static_cast<int>(i);
    return -1;
  }
  // Valid blocks whose pixels all lie on true plane `index` (-1: on clutter, the pillar here).
  std::vector<int> blocksOn(int index) const
  {
    std::vector<int> out;
    const int s = blockSize(params.normal_window, params.normal_stride);
    for (size_t b = 0; b < frame.blocks.size(); ++b)
    {
      if (!frame.blocks[b].valid) continue;
      const int bx = static_cast<int>(b) % frame.blocksX(), by = static_cast<int>(b) / frame.blocksX();
      bool all = true;
      for (int v = by * s; v < (by + 1) * s && all; ++v)
        for (int u = bx * s; u < (bx + 1) * s && all; ++u)
        {
          const size_t i = static_cast<size_t>(v) * rendered.width + u;
          all = std::isfinite(rendered.xyz[3 * i + 2]) && rendered.pixel_plane[i] == index;
        }
      if (all) out.push_back(static_cast<int>(b));
    }
    return out;
  }
  // The middle image row of the blocks.
  int wallRow(const std::vector<int>& blocks) const
  {
    int low = frame.blocksY(), high = 0;
    for (int b : blocks) low = std::min(low, b / frame.blocksX()), high = std::max(high, b / frame.blocksX());
    return (low + high) / 2;
  }
  HoughPeak peakOf(const TruePlane& truth) const
  {
    HoughPeak peak;
    peak.normal = truth.normal;
    peak.d = truth.d;
    peak.hough = param.toHough(truth.normal, truth.d);
    peak.value = 1000.0;
    return peak;
  }
};

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::acos(std::min(1.0, std::abs(a.dot(b)))); }
}  // namespace

TEST(PlanarityTests, AWallPassesAndAPillarFails)
{
  Frame f;
  const std::vector<int> wall = f.blocksOn(f.truePlane("wall"));
  const std::vector<int> pillar = f.blocksOn(-1);
  ASSERT_GT(wall.size(), 100u);
  ASSERT_GT(pillar.size(), 30u);
  EXPECT_TRUE(f.tests.isPlanarFit(f.tests.weightedMoments(wall), wall));
  EXPECT_TRUE(f.tests.halvesAgree(wall, 0, wall.size(), f.params.merge_angle));
  EXPECT_FALSE(f.tests.isPlanarFit(f.tests.weightedMoments(pillar), pillar));
}

TEST(PlanarityTests, AFaceBowedLikeCardboardPassesACanFails)
{
  // Real box faces bow by about 1/m (osd-learn); a can's side turns 30 times as fast. Both
  // patches are 15 cm wide, 1 m ahead: their halves tilt apart by more than merge_angle and
  // far beyond the noise, but only the can bends faster than a plane may (kMaxPlaneCurvature).
  for (const double radius : {1.0, 0.25})
  {
    Scene scene;
    scene.cylinders.push_back({Eigen::Vector3d(1.0 + radius, 0, 0), radius, 2.0});
    Frame f(scene, lookAt(Eigen::Vector3d(0, 0, 1.0), Eigen::Vector3d(1, 0, 1.0)));
    std::vector<int> patch;
    for (int b : f.blocksOn(-1))
      if (std::abs(f.frame.blocks[b].centroid.x()) < 0.075 && std::abs(f.frame.blocks[b].centroid.y()) < 0.2)
        patch.push_back(b);
    ASSERT_GT(patch.size(), 60u) << "radius " << radius;
    EXPECT_EQ(f.tests.halvesAgree(patch, 0, patch.size(), f.params.merge_angle), radius > 1.0 / kMaxPlaneCurvature)
        << "radius " << radius;
  }
}

TEST(PlanarityTests, TheLikelihoodRatioTellsTheTrueNormalFromOneDegreeOff)
{
  Frame f;
  const std::vector<int> wall = f.blocksOn(f.truePlane("wall"));
  const Eigen::Vector3d n_cam = f.frame.normalInCamera(f.renderer.truePlanes()[f.truePlane("wall")].normal);
  EXPECT_TRUE(f.tests.explainedByNormal(n_cam, wall));
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitX()) * n_cam;
  EXPECT_GT(f.tests.snapChi2Increase(tilted, wall), kMaxSnapChi2Increase);
  EXPECT_FALSE(f.tests.explainedByNormal(tilted, wall));
}

TEST(PlanarityTests, ANormalNeedsSpreadAcrossMoreThanAFewBlocks)
{
  Frame f;
  const std::vector<int> wall = f.blocksOn(f.truePlane("wall"));
  ASSERT_GT(wall.size(), 100u);
  const double bound = f.params.merge_angle / 2.0;  // FramePlaneFitter's limit
  EXPECT_LT(f.tests.normalUncertainty(wall), 0.2 * bound);
  // One image row of the wall's blocks: a line in space, no tilt about it is measured.
  const int row = f.wallRow(wall);
  std::vector<int> strip;
  for (int b : wall)
    if (b / f.frame.blocksX() == row) strip.push_back(b);
  ASSERT_GT(strip.size(), 20u);
  EXPECT_GT(f.tests.normalUncertainty(strip), bound);
  // Nor may a few blocks off the row (a strip along a shelf's edge and some on the wall).
  int added = 0;
  for (int b : wall)
    if (b / f.frame.blocksX() == row + 10 && added < 3) strip.push_back(b), ++added;
  ASSERT_EQ(added, 3);
  EXPECT_GT(f.tests.normalUncertainty(strip), bound);
  // Three rows do.
  for (int b : wall)
    if (b / f.frame.blocksX() == row + 1 || b / f.frame.blocksX() == row + 2) strip.push_back(b);
  EXPECT_LT(f.tests.normalUncertainty(strip), bound);
}

TEST(FramePlaneFitter, BothFitsRecoverTheFloorAndTheWallFromTheirPeaks)
{
  for (int region_growing = 0; region_growing <= 1; ++region_growing)
  {
    Frame f;
    f.params.region_growing = region_growing;
    FramePlaneFitter fitter(f.params, f.param, f.frame, f.tests);
    const TruePlane& floor = f.renderer.truePlanes()[f.truePlane("floor")];
    const TruePlane& wall = f.renderer.truePlanes()[f.truePlane("wall")];
    std::vector<FramePlane> planes;
    std::vector<PlaneCandidate> candidates;
    if (region_growing)
      fitter.growRegions({f.peakOf(floor), f.peakOf(wall)}, {}, planes, candidates);
    else
      fitter.fitWindows({f.peakOf(floor), f.peakOf(wall)}, {}, planes, candidates);
    SCOPED_TRACE(region_growing ? "block regions" : "windows");
    ASSERT_GE(planes.size(), 2u);
    for (const TruePlane* truth : {&floor, &wall})
    {
      int found = 0;
      for (const FramePlane& plane : planes)
        if (angleBetween(plane.normal, truth->normal) < 0.005 &&
            std::abs(std::abs(plane.d) - std::abs(truth->d)) < 0.005 && plane.support > 5000)
          ++found;
      EXPECT_EQ(found, 1) << truth->name;
    }
    EXPECT_EQ(candidates.front().verdict, CandidateVerdict::kAccepted);
    // What a plane took is claimed for the rest of the frame.
    size_t claimed = 0;
    for (char c : f.frame.block_claim) claimed += c;
    EXPECT_GT(claimed, 200u);
  }
}

TEST(ParallelPlanes, FindsTheStepFromTheFloorsNormalAndMeasuresTheMapsFloorAgain)
{
  Frame f;
  DetectedPlane floor;
  floor.normal = Eigen::Vector3d::UnitZ();
  floor.d = 0.0;
  auto count = [](const std::vector<FramePlane>& planes, double height) {
    int n = 0;
    for (const FramePlane& plane : planes)
      if (std::abs(std::abs(plane.d) - height) < 0.01 && std::abs(std::abs(plane.normal.z()) - 1.0) < 1e-9 && plane.parallel)
        ++n;
    return n;
  };
  // The floor from the map: a cluster on it measures it in this frame, the step is new.
  std::vector<FramePlane> planes;
  std::vector<PlaneCandidate> candidates;
  findParallelPlanes(f.params, f.param, f.frame, f.tests, {floor}, planes, candidates);
  EXPECT_EQ(count(planes, 0.2), 1);
  EXPECT_EQ(count(planes, 0.0), 1);
  // The floor found earlier in this frame is not found twice.
  Frame g;
  FramePlane frame_floor;
  frame_floor.normal = floor.normal;
  frame_floor.d = 0.0;
  planes.assign(1, frame_floor);
  findParallelPlanes(g.params, g.param, g.frame, g.tests, {}, planes, candidates);
  EXPECT_EQ(count(planes, 0.2), 1);
  EXPECT_EQ(count(planes, 0.0), 0);
  // Nothing is found without a known direction, or with the search off.
  planes.clear();
  findParallelPlanes(f.params, f.param, f.frame, f.tests, {}, planes, candidates);
  EXPECT_TRUE(planes.empty());
  f.params.parallel_support = 0;
  findParallelPlanes(f.params, f.param, f.frame, f.tests, {floor}, planes, candidates);
  EXPECT_TRUE(planes.empty());
}
