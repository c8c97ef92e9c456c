// The per-frame fits from Hough peaks (windows and block regions) on a rendered frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hough_plane_detector/core/frame_planes.h"
#include "frame_fixture.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

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

// A small far piece of the wall whose own fit came out nearer another known plane's normal
// (0.03 rad off, 1 m behind the piece) than the wall's: its blocks cannot tell the two
// directions apart, so the snap takes the wall's, the plane the piece lies on; with no
// such plane known it takes the nearest normal, as before.
TEST(FramePlaneFitter, ASnapPrefersTheKnownPlaneThePieceLiesOn)
{
  Frame f;
  FramePlaneFitter fitter(f.params, f.param, f.frame, f.tests);
  const TruePlane& wall = f.renderer.truePlanes()[f.truePlane("wall")];
  // A 3 x 3 block patch in the middle of the wall's blocks.
  const std::vector<int> wall_blocks = f.blocksOn(f.truePlane("wall"));
  ASSERT_FALSE(wall_blocks.empty());
  const int row = f.wallRow(wall_blocks), bx_count = f.frame.blocksX();
  int low = bx_count, high = 0;
  for (int b : wall_blocks)
    if (b / bx_count == row) low = std::min(low, b % bx_count), high = std::max(high, b % bx_count);
  const int column = (low + high) / 2;
  std::vector<int> piece;
  for (int y = row - 1; y <= row + 1; ++y)
    for (int x = column - 1; x <= column + 1; ++x) piece.push_back(y * bx_count + x);
  for (int b : piece) ASSERT_TRUE(std::find(wall_blocks.begin(), wall_blocks.end(), b) != wall_blocks.end());

  DetectedPlane known_wall;
  known_wall.normal = wall.normal;
  known_wall.d = wall.d;
  DetectedPlane turned;  // another surface's plane, turned 0.03 rad about the vertical, 1 m behind
  turned.normal = Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ()) * wall.normal;
  const Eigen::Vector3d on_wall = -wall.d * wall.normal;
  turned.d = -turned.normal.dot(on_wall + 1.0 * wall.normal);
  const Eigen::Vector3d piece_fit = Eigen::AngleAxisd(0.035, Eigen::Vector3d::UnitZ()) * wall.normal;

  Eigen::Vector3d normal = piece_fit;
  double d = wall.d;
  ASSERT_TRUE(fitter.snapToKnownDirection(normal, d, piece, {turned}, {}))
      << "the piece's blocks must not tell 0.03 rad, or the test shows nothing";
  EXPECT_LT(angleBetween(normal, turned.normal), 1e-9) << "alone, the nearest known normal is taken";

  normal = piece_fit;
  d = wall.d;
  ASSERT_TRUE(fitter.snapToKnownDirection(normal, d, piece, {turned, known_wall}, {}));
  EXPECT_LT(angleBetween(normal, wall.normal), 1e-9) << "the wall's normal, the plane the piece lies on";
  EXPECT_NEAR(std::abs(d), std::abs(wall.d), 0.02);
}

// A 3 x 3 block piece of the wall and a surface turned 0.03 rad about the vertical, 1 m behind
// it, that its blocks cannot tell from the wall. As a map plane (measured in earlier frames)
// its direction is taken; as another region of this frame, with the world's up known, it is
// not: that region shares this frame's depth errors, which real cameras correlate over many
// pixels (a frame's walls turned alike). A floor piece still takes a level region's direction
// of this frame (gravity's), and without an up this frame's surfaces are the only references.
TEST(FramePlaneFitter, WithTheUpKnownAFaceTakesADirectionOffTheVerticalOnlyFromTheMap)
{
  Frame f;
  struct Case
  {
    const char* plane;
    double turn;
    Eigen::Vector3d axis;
    bool frame_direction_taken_with_up;
  };
  for (const Case& c : {Case{"wall", 0.03, Eigen::Vector3d::UnitZ(), false},
                        Case{"floor", 0.01, Eigen::Vector3d::UnitY(), true}})
  {
    const TruePlane& truth = f.renderer.truePlanes()[f.truePlane(c.plane)];
    const std::vector<int> blocks = f.squareOn(c.plane, 3);
    ASSERT_EQ(blocks.size(), 9u) << c.plane;
    const Eigen::Vector3d turned_normal = Eigen::AngleAxisd(c.turn, c.axis) * truth.normal;
    const double turned_d = -turned_normal.dot(-truth.d * truth.normal + 1.0 * truth.normal);
    DetectedPlane in_map;
    in_map.normal = turned_normal;
    in_map.d = turned_d;
    FramePlane in_frame;
    in_frame.normal = turned_normal;
    in_frame.d = turned_d;
    for (int up_known = 0; up_known <= 1; ++up_known)
    {
      f.params.world_z_up = up_known;
      FramePlaneFitter fitter(f.params, f.param, f.frame, f.tests);
      SCOPED_TRACE(std::string(c.plane) + ", world_z_up " + std::to_string(up_known));
      Eigen::Vector3d normal = truth.normal;
      double d = truth.d;
      ASSERT_TRUE(fitter.snapToKnownDirection(normal, d, blocks, {in_map}, {}))
          << "the piece's blocks must not tell the turn, or this shows nothing";
      EXPECT_LT(angleBetween(normal, turned_normal), 1e-9);
      normal = truth.normal;
      d = truth.d;
      const bool taken = !up_known || c.frame_direction_taken_with_up;
      EXPECT_EQ(fitter.snapToKnownDirection(normal, d, blocks, {}, {in_frame}), taken);
      EXPECT_LT(angleBetween(normal, taken ? turned_normal : truth.normal), 1e-9);
    }
  }
}

// A wall patch of 81 blocks and a known plane turned 0.02 rad about the vertical: the noise
// model cannot tell the two normals apart (rendered faces scatter well below it), the
// patch's own scatter can. With the world's up known, a face off the vertical keeps its own
// normal (boxes at any yaw are parallel only by chance); a floor patch still takes a known
// normal as far off, since level surfaces are parallel by gravity. With up unknown no normal
// is known to be level: both keep their own normal against another surface's (the known
// plane 0.5 m off the patch) and both take the known normal of a plane they lie on (their
// own surface re-measured).
TEST(FramePlaneFitter, AFaceOffTheVerticalSnapsOnlyIfItsOwnScatterCannotTellTheNormals)
{
  Frame f;
  struct Case
  {
    const char* plane;
    int k;
    double turn;
    Eigen::Vector3d axis;
    bool snaps_with_up_known;
  };
  for (const Case& c : {Case{"wall", 9, 0.02, Eigen::Vector3d::UnitZ(), false},
                        Case{"floor", 9, 0.01, Eigen::Vector3d::UnitY(), true}})
  {
    const TruePlane& truth = f.renderer.truePlanes()[f.truePlane(c.plane)];
    const std::vector<int> blocks = f.squareOn(c.plane, c.k);
    ASSERT_GT(blocks.size(), 40u) << c.plane;
    PointMoments points;
    for (int b : blocks) points.add(f.frame.moments(b));
    const Eigen::Vector3d centroid = f.frame.camera_to_world * points.mean();
    DetectedPlane known;
    known.normal = Eigen::AngleAxisd(c.turn, c.axis) * truth.normal;
    const PlanarityTests::NormalExplanation explained =
        f.tests.explainNormal(f.frame.normalInCamera(known.normal), blocks, false);
    ASSERT_TRUE(explained.interior) << c.plane << ": the noise model must not tell the normals, or this shows nothing";
    ASSERT_FALSE(explained.interior_within_own_scatter) << c.plane << ": its own scatter must tell them";
    for (double off_the_patch : {0.0, 0.5})
    {
      known.d = -known.normal.dot(centroid) + off_the_patch;
      for (int up_known = 0; up_known <= 1; ++up_known)
      {
        f.params.world_z_up = up_known;
        FramePlaneFitter fitter(f.params, f.param, f.frame, f.tests);
        Eigen::Vector3d normal = truth.normal;
        double d = truth.d;
        const bool snaps = up_known ? c.snaps_with_up_known : off_the_patch == 0.0;
        EXPECT_EQ(fitter.snapToKnownDirection(normal, d, blocks, {known}, {}), snaps)
            << c.plane << ", world_z_up " << up_known << ", known plane " << off_the_patch << " m off the patch";
      }
    }
  }
}

// A table's top 3 m away, 45 cm below the camera, grown as a region with the floor known: rim
// blocks at its far edge lean over it, its own fit tilts and it takes the floor's normal. The
// snapped plane is measured by the blocks on it (its whole region's centroids lie off it beyond
// their noise), and those fit it: one frame is a complete measurement of it (first sight).
TEST(FramePlaneFitter, ASnappedPlaneIsJudgedOnTheBlocksThatMeasuredIt)
{
  Scene scene;
  scene.addRectangle(Eigen::Vector3d(3, 0, 0), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 5, 3, "floor");
  scene.addBox(Eigen::Vector3d(3.0, 0.0, 0.73), Eigen::Vector3d(0.4, 0.7, 0.02), 0.3, "table");
  Frame f(scene, lookAt(Eigen::Vector3d(0, 0, 1.2), Eigen::Vector3d(3.0, 0, 0.0)));
  FramePlaneFitter fitter(f.params, f.param, f.frame, f.tests);
  const TruePlane& floor = f.renderer.truePlanes()[f.truePlane("floor")];
  const TruePlane& top = f.renderer.truePlanes()[f.truePlane("table_top")];
  DetectedPlane known_floor;
  known_floor.normal = floor.normal;
  known_floor.d = floor.d;
  std::vector<FramePlane> planes;
  std::vector<PlaneCandidate> candidates;
  fitter.growRegions({f.peakOf(top)}, {known_floor}, planes, candidates);
  const FramePlane* table_top = nullptr;
  for (const FramePlane& plane : planes)
    if (angleBetween(plane.normal, top.normal) < 0.01 && std::abs(std::abs(plane.d) - std::abs(top.d)) < 0.01)
      table_top = &plane;
  ASSERT_NE(table_top, nullptr);
  ASSERT_TRUE(table_top->parallel) << "the table's top takes the floor's normal";
  EXPECT_LT(angleBetween(table_top->normal, floor.normal), 1e-9);
  ASSERT_GT(f.tests.centroidChi2(f.frame.normalInCamera(table_top->normal),
                                 f.frame.dInCamera(table_top->normal, table_top->d), table_top->blocks),
            1.0)
      << "the whole region must lie off the plane beyond its noise, or the test shows nothing";
  EXPECT_TRUE(table_top->fits_its_blocks);
  EXPECT_FALSE(table_top->mixes_surfaces);
}

namespace
{
// The regions grown from the lower box's back include a plane of each box's back (boxes
// "lower" and "upper"), each within 0.01 rad and 1 cm, of 100+ blocks that fit it, and no region
// of 100+ blocks that mixes surfaces.
void expectBothBacksMeasured(const Scene& scene, const Eigen::Isometry3d& camera_to_world)
{
  Frame f(scene, camera_to_world);
  FramePlaneFitter fitter(f.params, f.param, f.frame, f.tests);
  const TruePlane& lower = f.renderer.truePlanes()[f.truePlane("lower_back")];
  const TruePlane& upper = f.renderer.truePlanes()[f.truePlane("upper_back")];
  std::vector<FramePlane> planes;
  std::vector<PlaneCandidate> candidates;
  fitter.growRegions({f.peakOf(lower)}, {}, planes, candidates);
  auto measured = [&](const TruePlane& truth) {
    for (const FramePlane& plane : planes)
      if (angleBetween(plane.normal, truth.normal) < 0.01 && std::abs(std::abs(plane.d) - std::abs(truth.d)) < 0.01 &&
          plane.fits_its_blocks && plane.blocks.size() >= 100)
        return true;
    return false;
  };
  EXPECT_TRUE(measured(lower)) << "the lower box's back, within 0.01 rad and 1 cm, fitting its blocks";
  EXPECT_TRUE(measured(upper)) << "the upper box's back, within 0.01 rad and 1 cm, fitting its blocks";
  for (const FramePlane& plane : planes)
    EXPECT_FALSE(plane.blocks.size() >= 100 && plane.mixes_surfaces) << "a large region mixes the two backs";
}
}  // namespace

TEST(FramePlaneFitter, ARegionOverTwoStackedFacesIsSplitIntoTheirPlanes)
{
  // Two stacked boxes, the upper turned 0.07 rad about their shared back edge: their backs meet
  // at the edge and one region grows over both, its plane between them.
  Scene scene;
  scene.addRectangle(Eigen::Vector3d(3, 0, 0), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 5, 3, "floor");
  const double yaw = 0.07;
  const Eigen::Vector3d half(0.3, 0.4, 0.25), edge(2.0, -0.4, 0.0), to_centre(0.3, 0.4, 0.0);
  scene.addBox(edge + to_centre + Eigen::Vector3d(0, 0, 0.25), half, 0.0, "lower");
  scene.addBox(edge + Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * to_centre + Eigen::Vector3d(0, 0, 0.75), half,
               yaw, "upper");
  expectBothBacksMeasured(scene, lookAt(Eigen::Vector3d(0, 0.3, 1.0), Eigen::Vector3d(2.0, 0, 0.5)));
}

TEST(FramePlaneFitter, ARegionOverTwoFacesThatCrossMidwayIsSplitIntoTheirPlanes)
{
  // The upper box turned 0.07 rad about its own centre: the two backs cross in the middle of the
  // region, and the blocks on both sides of the crossing lie on either plane within their noise
  // at 2.5 m, so the assignment by distance scatters them across it and neither part is one
  // piece. Grown over the blocks that lie on its plane, each part is one piece again: the region
  // is split into the two backs.
  Scene scene;
  scene.addRectangle(Eigen::Vector3d(3, 0, 0), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 5, 3, "floor");
  const Eigen::Vector3d half(0.3, 0.4, 0.25);
  scene.addBox(Eigen::Vector3d(2.8, 0.0, 0.25), half, 0.0, "lower");
  scene.addBox(Eigen::Vector3d(2.8, 0.0, 0.75), half, 0.07, "upper");
  expectBothBacksMeasured(scene, lookAt(Eigen::Vector3d(0, 0.3, 1.2), Eigen::Vector3d(2.5, 0, 0.5)));
}

// A wall of which only two block rows, 16 blocks long, are measured flat (the rest as if
// cluttered): its points cannot orient it, so without the world's up it is refused; with it
// (world_z_up) it is the upright plane through them, the wall's.
TEST(FramePlaneFitter, AnUnorientedStripIsKeptUprightWhenTheWorldsUpIsKnown)
{
  for (int world_z_up = 0; world_z_up <= 1; ++world_z_up)
  {
    Frame f;
    f.params.world_z_up = world_z_up;
    const TruePlane& wall = f.renderer.truePlanes()[f.truePlane("wall")];
    const std::vector<int> wall_blocks = f.blocksOn(f.truePlane("wall"));
    const int row = f.wallRow(wall_blocks), column = f.frame.blocksX() / 2;
    for (size_t b = 0; b < f.frame.blocks.size(); ++b)
    {
      const int by = static_cast<int>(b) / f.frame.blocksX(), bx = static_cast<int>(b) % f.frame.blocksX();
      if (by < row || by > row + 1 || bx < column - 8 || bx >= column + 8) f.frame.blocks[b].planar = false;
    }
    FramePlaneFitter fitter(f.params, f.param, f.frame, f.tests);
    std::vector<FramePlane> planes;
    std::vector<PlaneCandidate> candidates;
    fitter.growRegions({f.peakOf(wall)}, {}, planes, candidates);
    SCOPED_TRACE(world_z_up ? "world_z_up 1" : "world_z_up 0");
    ASSERT_FALSE(candidates.empty());
    const PlaneCandidate& first = candidates.front();
    if (!world_z_up)
    {
      EXPECT_EQ(first.verdict, CandidateVerdict::kNormalUndetermined);
      EXPECT_TRUE(planes.empty());
      continue;
    }
    EXPECT_EQ(first.verdict, CandidateVerdict::kAccepted);
    ASSERT_EQ(planes.size(), 1u);
    EXPECT_TRUE(planes[0].upright);
    EXPECT_EQ(planes[0].normal.z(), 0.0);
    EXPECT_LT(angleBetween(planes[0].normal, wall.normal), 0.01);
    EXPECT_LT(planes[0].normal_sigma, f.params.merge_angle / 2.0);
    EXPECT_LT(std::abs(std::abs(planes[0].d) - std::abs(wall.d)), 0.01);
  }
}
