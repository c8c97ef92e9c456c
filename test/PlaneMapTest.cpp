// The persistent map (paper 3.6-3.7, Alg. 2) fed with per-frame planes directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hough_plane_detector/core/plane_geometry.h"
#include "hough_plane_detector/core/plane_map.h"

using namespace hough_plane_detector;

namespace
{
struct Map
{
  DetectorParams params;
  HoughParameterization param{params.effectiveAngleStep(), params.effectiveDStep(), params.max_distance,
                              params.blur_kernel_size / 2 + params.peak_window / 2 + 2};
  HoughVoting voting{param, params.blur_kernel_size / 2, params.blur_sigma};
  HoughPeakSearch search{param, params.peak_window / 2};
  PlaneMap map{params, param, voting, search};

  // first_sight_points < 0: as many as its points (all at kStrongSupportDepth or beyond).
  FramePlane plane(const Eigen::Vector3d& normal, double d, double support, double first_sight_points = -1.0) const
  {
    FramePlane p;
    p.normal = normal.normalized();
    p.d = d;
    p.hough = param.toHough(p.normal, d);
    p.support = support;
    p.first_sight_points = first_sight_points < 0.0 ? support : first_sight_points;
    return p;
  }
  // A region that fits its blocks, measured at `centroid` with the given normal's sigma and an
  // offset sigma of 1 mm.
  FramePlane fitting(const Eigen::Vector3d& normal, const Eigen::Vector3d& centroid, double support,
                     double normal_sigma = 0.002) const
  {
    FramePlane p = plane(normal, -normal.normalized().dot(centroid), support);
    p.blocks = {1, 2, 3};
    p.fits_its_blocks = true;
    p.normal_sigma = normal_sigma;
    p.offset_sigma = 0.001;
    p.centroid = centroid;
    return p;
  }
  void frame(const std::vector<FramePlane>& planes, double stamp,
             const Eigen::Vector3d& camera_position = Eigen::Vector3d::Zero())
  {
    map.beginFrame();
    map.accumulate(planes, camera_position, stamp);
  }
};
const Eigen::Vector3d kFloor = Eigen::Vector3d::UnitZ();

std::vector<const DetectedPlane*> matching(const std::vector<DetectedPlane>& planes, const Eigen::Vector3d& normal)
{
  std::vector<const DetectedPlane*> found;
  for (const DetectedPlane& plane : planes)
    if (std::abs(plane.normal.dot(normal)) > 0.999) found.push_back(&plane);
  return found;
}
}  // namespace

TEST(PlaneMap, AWeakPlaneNeedsASecondFrameAStrongOneDoesNot)
{
  Map m;
  m.frame({m.plane(kFloor, 1.0, 3000)}, 0.0);  // 3,000 points: adds 1 + 3000 / 16000 < global_threshold
  EXPECT_TRUE(m.map.planes().empty());
  m.frame({m.plane(kFloor, 1.0, 3000)}, 1.0);
  ASSERT_EQ(m.map.planes().size(), 1u);
  EXPECT_EQ(m.map.planes()[0].first_seen, 1.0);

  Map strong;
  strong.frame({strong.plane(Eigen::Vector3d(1, 0, 0), -2.0, 16000)}, 0.0);
  ASSERT_EQ(strong.map.planes().size(), 1u);
  const DetectedPlane& wall = strong.map.planes()[0];
  EXPECT_LT(std::acos(std::abs(wall.normal.x())), 0.002);
  EXPECT_NEAR(std::abs(wall.d), 2.0, 0.005);
  EXPECT_GT(wall.normal.dot(Eigen::Vector3d::Zero()) + wall.d, 0.0);  // faces the sensor at the origin
}

TEST(PlaneMap, AStrongPlaneIsReportedAtFirstSightWhereverBetweenTheCellsItFalls)
{
  // Half a cell off on every Hough axis, a vote of 2 reads 1.37 at its nearest cell, under
  // global_threshold 1.5: a plane of strong_support points is still reported from its frame.
  // One of 0.6 strong_support (a vote of 1.6) is judged by its cell and waits there.
  Map probe;
  const Eigen::Vector3d hough = probe.param.toHough(Eigen::Vector3d(0.3, -0.2, 1.0).normalized(), -1.2);
  const Eigen::Vector3d corner = probe.param.toCell(hough).array().floor() + 0.5;  // between 8 cells
  Eigen::Vector3d normal;
  double d;
  probe.param.fromHough(probe.param.fromCell(corner), normal, d);
  Map strong;
  strong.frame({strong.plane(normal, d, strong.params.strong_support)}, 0.0);
  EXPECT_EQ(strong.map.planes().size(), 1u);
  Map weaker;
  weaker.frame({weaker.plane(normal, d, 0.6 * weaker.params.strong_support)}, 0.0);
  EXPECT_TRUE(weaker.map.planes().empty());
}

TEST(PlaneMap, NearPointsCountByTheirPrecisionButASmallPatchWaits)
{
  // 3,000 points at 1 m measure a plane like 48,000 at 2 m (Kinect noise grows with depth^2).
  Map near;
  near.frame({near.plane(kFloor, 1.0, 3000, 48000)}, 0.0);
  EXPECT_EQ(near.map.planes().size(), 1u);
  // Under 2 min_support points no frame alone reports it, however near: its own normal is too
  // poorly tested (a fold at a depth-distorted image corner passes).
  Map small;
  small.frame({small.plane(kFloor, 1.0, 2 * small.params.min_support - 1, 1e6)}, 0.0);
  EXPECT_TRUE(small.map.planes().empty());
}

TEST(PlaneMap, ASmallPatchParallelToAKnownPlaneIsReportedAtFirstSightOnlyWithTheFullBar)
{
  // A box top beside the table: 1,400 points at 0.6 m. Its normal is the known one, only its
  // offset is measured. Too small for the curvature tests, it earns no discount (a pillar's strip
  // fits a wall's normal too): its precision-weighted points must reach strong_support itself.
  const double small_support = 1400;
  Map near;
  FramePlane top = near.plane(kFloor, 1.0, small_support, near.params.strong_support);
  top.parallel = true;
  near.frame({top}, 0.0);
  EXPECT_EQ(near.map.planes().size(), 1u);
  // With its weighted points just under the bar (farther away) it waits for a second frame,
  // though a parallel plane of 2 min_support points needs only a quarter of the bar.
  Map far;
  FramePlane strip = far.plane(kFloor, 1.0, small_support, 0.9 * far.params.strong_support);
  strip.parallel = true;
  far.frame({strip}, 0.0);
  EXPECT_TRUE(far.map.planes().empty());
  Map larger;
  FramePlane shelf = larger.plane(kFloor, 1.0, 2 * larger.params.min_support, 0.3 * larger.params.strong_support);
  shelf.parallel = true;
  larger.frame({shelf}, 0.0);
  EXPECT_EQ(larger.map.planes().size(), 1u);
}

// The quarter bar is for a plane that measured only its offset on one surface. A grown region
// snapped to a known normal whose blocks do not fit it mixes surfaces: it needs the full bar.
TEST(PlaneMap, AParallelRegionThatDoesNotFitItsBlocksNeedsTheFullFirstSightBar)
{
  struct Case
  {
    bool grown, fits;
    double weighted_share;  // of strong_support
    bool reported;
  };
  for (const Case& c : {Case{false, false, 0.3, true}, Case{true, true, 0.3, true}, Case{true, false, 0.3, false},
                        Case{true, false, 1.0, true}})
  {
    Map m;
    FramePlane shelf = m.plane(kFloor, 1.0, 3 * m.params.min_support, c.weighted_share * m.params.strong_support);
    shelf.parallel = true;
    if (c.grown) shelf.blocks = {1, 2, 3};
    shelf.fits_its_blocks = c.fits;
    // Too imprecise for the first sight of a fitting region: only the bar decides.
    shelf.normal_sigma = 0.05;
    m.frame({shelf}, 0.0);
    EXPECT_EQ(m.map.planes().size(), c.reported ? 1u : 0u)
        << (c.grown ? "grown region" : "parallel search") << ", fits " << c.fits << ", weighted points "
        << c.weighted_share << " strong_support";
  }
}

TEST(PlaneMap, TwoPatchesOfOneSurfaceInOneFrameArePooledForTheFirstSightBar)
{
  // A box top at 0.55 m grown as two regions (0.5 cm and 0.03 rad apart, within the merge
  // tolerances): each alone is under the parallel bar and waits; together they measure one
  // plane, reported at first sight. Two patches 4 cm apart are two planes and each waits.
  const double support = 1088, weighted = 0.9 * Map().params.strong_support;
  auto patch = [&](Map& m, const Eigen::Vector3d& normal, double d) {
    FramePlane p = m.plane(normal, d, support, weighted);
    p.parallel = true;
    return p;
  };
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitX()) * kFloor;
  Map alone;
  alone.frame({patch(alone, kFloor, -0.524)}, 0.0);
  EXPECT_TRUE(alone.map.planes().empty());
  Map split;
  split.frame({patch(split, kFloor, -0.524), patch(split, tilted, -0.519)}, 0.0);
  ASSERT_EQ(split.map.planes().size(), 1u);
  EXPECT_NEAR(std::abs(split.map.planes()[0].d), 0.52, 0.006);
  Map apart;
  apart.frame({patch(apart, kFloor, -0.524), patch(apart, kFloor, -0.564)}, 0.0);
  EXPECT_TRUE(apart.map.planes().empty());
  // Pooling decides only whether the surface is too small to be judged; each region still votes
  // its own weight: two large regions 2.5 cm apart, 0.3 strong_support each, wait as each would
  // alone.
  Map weak;
  const double half_bar = 0.3 * weak.params.strong_support;
  weak.frame({weak.plane(kFloor, -1.0, 4000, half_bar), weak.plane(kFloor, -1.025, 4000, half_bar)}, 0.0);
  EXPECT_TRUE(weak.map.planes().empty());
}

TEST(PlaneMap, IdsFollowAPlaneThatMovesALittleAndNewPlanesGetNewOnes)
{
  Map m;
  for (int f = 0; f < 3; ++f) m.frame({m.plane(kFloor, 1.0, 20000)}, f);
  ASSERT_EQ(m.map.planes().size(), 1u);
  const int floor_id = m.map.planes()[0].id;
  for (int f = 3; f < 6; ++f)
    m.frame({m.plane(Eigen::AngleAxisd(0.004, Eigen::Vector3d::UnitY()) * kFloor, 1.006, 20000),
             m.plane(Eigen::Vector3d(0, 1, 0), -3.0, 20000)},
            f);
  ASSERT_EQ(m.map.planes().size(), 2u);
  for (const DetectedPlane& plane : m.map.planes())
  {
    if (std::abs(plane.normal.z()) > 0.9)
      EXPECT_EQ(plane.id, floor_id);
    else
      EXPECT_NE(plane.id, floor_id);
  }
}

// Two box tops 3.2 cm apart, each measured in the frame: their Gaussians pull the two peaks'
// sub-voxel means under merge_distance, but a frame that measured two planes there saw two
// surfaces, and the map keeps them apart also when the next frames see only one of them.
// One face split into two regions of this frame (0.5 cm, 0.03 rad apart) stays one plane.
TEST(PlaneMap, PlanesOneFrameMeasuredApartStayApartAndASplitFaceStaysOne)
{
  auto offsets = [](const std::vector<DetectedPlane>& planes) {
    std::vector<double> d;
    for (const DetectedPlane& plane : planes) d.push_back(std::abs(plane.d));
    std::sort(d.begin(), d.end());
    return d;
  };
  Map tops;
  for (int f = 0; f < 4; ++f)
  {
    tops.frame({tops.plane(kFloor, -0.500, 20000), tops.plane(kFloor, -0.532, 20000)}, f);
    const std::vector<double> d = offsets(tops.map.planes());
    ASSERT_EQ(d.size(), 2u) << "frame " << f;
    EXPECT_NEAR(d[0], 0.500, 0.006);  // each Gaussian's tail pulls the other's mean a little
    EXPECT_NEAR(d[1], 0.532, 0.006);
  }
  for (int f = 4; f < 8; ++f)
  {
    tops.frame({tops.plane(kFloor, -0.500, 20000)}, f);
    const std::vector<double> d = offsets(tops.map.planes());
    ASSERT_EQ(d.size(), 2u) << "frame " << f;
    EXPECT_NEAR(d[0], 0.500, 0.006);
    EXPECT_NEAR(d[1], 0.532, 0.006);
  }

  Map split;
  split.frame({split.plane(kFloor, -0.500, 20000),
               split.plane(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitX()) * kFloor, -0.505, 20000)},
              0.0);
  EXPECT_EQ(split.map.planes().size(), 1u);
}

TEST(PlaneMap, TwoSurfacesOneFrameMeasuredCloserThanTheMergeDistanceStayTwo)
{
  // A box top and a lid 2.9 cm apart (under merge_distance 3 cm, three d cells: two maxima):
  // eq. 7-8 alone would report one plane between them. One frame measured both, with
  // millimetre offset errors and nothing between them but their warp: two surfaces. One face
  // grown as two regions 5 mm and 0.03 rad apart, 30 cm from each other, stays one plane.
  auto measured = [](FramePlane plane, const Eigen::Vector3d& centroid) {
    plane.centroid = centroid;
    plane.offset_sigma = 0.001;
    return plane;
  };
  Map tops;
  for (int f = 0; f < 4; ++f)
  {
    tops.frame({measured(tops.plane(kFloor, -0.500, 20000), Eigen::Vector3d(0.2, 0.0, 0.500)),
                measured(tops.plane(kFloor, -0.529, 20000), Eigen::Vector3d(-0.1, 0.1, 0.529))},
               f);
    std::vector<double> d;
    for (const DetectedPlane& plane : tops.map.planes()) d.push_back(std::abs(plane.d));
    std::sort(d.begin(), d.end());
    ASSERT_EQ(d.size(), 2u) << "frame " << f;
    // Each Gaussian's tail pulls the other's sub-voxel mean 6-7 mm this close (the midpoint: 14.5).
    EXPECT_NEAR(d[0], 0.500, 0.008);
    EXPECT_NEAR(d[1], 0.529, 0.008);
  }
  Map split;
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitX()) * kFloor;
  split.frame({measured(split.plane(kFloor, -0.500, 20000), Eigen::Vector3d(0.0, 0.0, 0.500)),
               measured(split.plane(tilted, -tilted.dot(Eigen::Vector3d(0.0, 0.3, 0.505)), 20000),
                        Eigen::Vector3d(0.0, 0.3, 0.505))},
              0.0);
  EXPECT_EQ(split.map.planes().size(), 1u);
}

// Two table tops 1.8 cm apart (two d cells) climb to one maximum of the space; one frame that
// measured both, each fitting its blocks and precise, parts them (addCloseSurfacePeaks). The
// split needs both sides trusted and parallel within their normals' noise: a region that does
// not fit its blocks, or one tilted beyond that noise, beside the floor is that floor fitted
// badly (a snapped stretch of floor 0.012 rad off in a held-out room), not a second surface,
// and the maximum stays one plane.
TEST(PlaneMap, ASharedMaximumSplitsOnlyForTwoTrustedParallelSurfaces)
{
  auto measured = [](FramePlane plane, const Eigen::Vector3d& centroid, double normal_sigma, bool fits) {
    plane.centroid = centroid;
    plane.offset_sigma = 0.001;
    plane.normal_sigma = normal_sigma;
    plane.fits_its_blocks = fits;
    return plane;
  };
  const Eigen::Vector3d camera(0.0, 0.0, 1.5);
  Map tops;
  tops.frame({measured(tops.plane(kFloor, -0.750, 20000), Eigen::Vector3d(1.5, -0.45, 0.750), 0.002, true),
              measured(tops.plane(kFloor, -0.768, 20000), Eigen::Vector3d(1.5, 0.45, 0.768), 0.002, true)},
             0.0, camera);
  std::vector<double> d;
  for (const DetectedPlane& plane : tops.map.planes()) d.push_back(std::abs(plane.d));
  std::sort(d.begin(), d.end());
  ASSERT_EQ(d.size(), 2u);
  EXPECT_NEAR(d[0], 0.750, 0.006);
  EXPECT_NEAR(d[1], 0.768, 0.006);

  // A floor seen for a while and, in each of the next six frames, a region 20 cm beside and
  // 2.5 cm above its centroid, tilted 0.012 rad: its votes climb to the floor's maximum, and by
  // their offsets the two would be two surfaces (distinctSurfaces) were the region trusted and
  // parallel to it. Without the guard its own peak becomes a second plane from the second frame.
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(0.012, Eigen::Vector3d::UnitX()) * kFloor;
  const Eigen::Vector3d off_centroid(2.0, 0.5, 0.025);
  struct Case
  {
    double normal_sigma;
    bool fits;
    const char* what;
  };
  for (const Case& c : {Case{0.05, false, "not fitting its blocks"}, Case{0.002, true, "tilted beyond its noise"}})
  {
    Map floor;
    const FramePlane seen = measured(floor.plane(kFloor, 0.0, 20000), Eigen::Vector3d(2.0, 0.3, 0.0), 0.002, true);
    for (int f = 0; f < 6; ++f) floor.frame({seen}, f, camera);
    const FramePlane region =
        measured(floor.plane(tilted, -tilted.dot(off_centroid), 20000), off_centroid, c.normal_sigma, c.fits);
    for (int f = 6; f < 12; ++f)
    {
      floor.frame({seen, region}, f, camera);
      if (floor.map.planes().size() != 1u)
      {
        ADD_FAILURE() << c.what << ", frame " << f << ": " << floor.map.planes().size() << " planes";
        break;
      }
      EXPECT_LT(std::acos(std::abs(floor.map.planes()[0].normal.z())), 0.003) << c.what << ", frame " << f;
      // The region's votes pull the shared maximum's mean a few millimetres off the floor.
      EXPECT_LT(std::abs(floor.map.planes()[0].d), 0.006) << c.what << ", frame " << f;
    }
  }
}

// A plane one frame raised that no later frame supports: the paper's thinning takes it away at
// thinning_rate a frame; forgetting by evidence (the default) takes a tentative plane away at
// PlaneBelief::kTentativeFade a frame.
TEST(PlaneMap, ThinningForgetsAPlaneNoFrameConfirms)
{
  for (int forgetting : {kForgetByThinning, kForgetByEvidence})
  {
    Map m;
    m.params.forgetting = forgetting;
    m.frame({m.plane(kFloor, 1.0, 20000)}, 0.0);
    ASSERT_EQ(m.map.planes().size(), 1u);
    // Peak 2 thins to below global_threshold after (2 - 1.5) / rate frames.
    int frames_kept = 0;
    for (int f = 1; f < 40 && !m.map.planes().empty(); ++f, ++frames_kept) m.frame({}, f);
    EXPECT_TRUE(m.map.planes().empty());
    const double rate = forgetting == kForgetByThinning ? m.params.thinning_rate : PlaneBelief::kTentativeFade;
    EXPECT_NEAR(frames_kept, (2.0 - m.params.global_threshold) / rate, 1.5) << "forgetting " << forgetting;
  }
}

// Forgetting by evidence: a tentative plane loses kTentativeFade in a frame that does not measure
// it again, thinning_rate in one that does.
TEST(PlaneMap, ATentativePlaneFadesOnlyInFramesThatDoNotMeasureItAgain)
{
  Map m;
  m.frame({m.plane(kFloor, 1.0, 20000)}, 0.0);
  ASSERT_EQ(m.map.planes().size(), 1u);
  const double born = m.map.planes()[0].strength;
  m.frame({m.plane(kFloor, 1.0, 1000)}, 1.0);  // measured again: thinned, plus one vote
  ASSERT_EQ(m.map.planes().size(), 1u);
  const double remeasured = m.map.planes()[0].strength;
  EXPECT_NEAR(remeasured, born - m.params.thinning_rate + 1.0, 0.1);  // sub-cell peaks: not exactly additive
  m.frame({m.plane(Eigen::Vector3d(1, 0, 0), -2.0, 1000)}, 2.0);  // a wall only: the floor is not measured
  ASSERT_EQ(matching(m.map.planes(), kFloor).size(), 1u);
  EXPECT_NEAR(matching(m.map.planes(), kFloor)[0]->strength, remeasured - PlaneBelief::kTentativeFade, 0.1);
}

// A region that fits its blocks is reported from one frame only when it is precise enough that
// a second measurement would agree with it: its normal, and its offset at its own points, within
// the merge tolerances at 2 sigma of the difference of two measurements. How far the points lie
// from the world origin (the lever arm of a tilt error there) does not matter.
TEST(PlaneMap, AFittingRegionIsReportedAtFirstSightOnlyWhenPrecise)
{
  struct Case
  {
    double normal_sigma, offset_sigma;
    Eigen::Vector3d centroid;
    bool reported;
  };
  // merge_angle 0.05, merge_distance 0.03: at 2 sqrt(2) sigma, sigma_n <= 0.0177 and the
  // offset's sigma <= 0.0106 m. A wall x = 2 (normal x): the lever is the centroid's (y, z).
  for (const Case& c : {Case{0.002, 0.001, {2.0, 0.0, 1.0}, true}, Case{0.02, 0.001, {2.0, 0.0, 1.0}, false},
                        Case{0.002, 0.012, {2.0, 0.0, 1.0}, false}, Case{0.002, 0.001, {2.0, 6.0, 1.0}, true}})
  {
    Map m;
    FramePlane wall = m.plane(Eigen::Vector3d(1, 0, 0), -2.0, 3000);  // 3,000 points: 1.19 by its points
    wall.fits_its_blocks = true;
    wall.normal_sigma = c.normal_sigma;
    wall.offset_sigma = c.offset_sigma;
    wall.centroid = c.centroid;
    m.frame({wall}, 0.0);
    EXPECT_EQ(m.map.planes().size(), c.reported ? 1u : 0u)
        << "normal sigma " << c.normal_sigma << ", offset sigma " << c.offset_sigma << ", lever "
        << c.centroid.tail<2>().norm() << " m";
  }
}

// Each frame plane says how it voted, and the map's first-sight reports follow it: only a
// complete measurement of a new surface is reported from this one frame.
TEST(PlaneMap, EachFramePlaneSaysHowItVotedAtFirstSight)
{
  Map m;
  const FramePlane wall = m.fitting(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(2.0, 0.0, 1.0), 20000);
  m.frame({wall}, 0.0);
  ASSERT_EQ(m.map.lastFirstSights(), std::vector<FirstSight>{FirstSight::kComplete});

  // New faces 3,000 points strong (1.19 by their points alone), each in its own direction.
  auto face = [&](double yaw, bool fits, double normal_sigma) {
    const Eigen::Vector3d normal(std::cos(yaw), std::sin(yaw), 0.0);
    FramePlane p = m.fitting(normal, 3.0 * normal + Eigen::Vector3d(0.0, 0.0, 1.0), 3000, normal_sigma);
    p.fits_its_blocks = fits;
    return p;
  };
  FramePlane mixing = face(2.0, false, 0.002);
  mixing.mixes_surfaces = true;
  FramePlane small = face(2.5, true, 0.002);
  small.support = small.first_sight_points = m.params.min_support;
  // Turned 0.08 rad about a point on the wall: possibly the wall measured badly.
  const FramePlane near_wall =
      m.fitting(Eigen::Vector3d(std::cos(0.08), std::sin(0.08), 0.0), Eigen::Vector3d(2.0, 0.0, 1.0), 3000);
  // The parallel search's planes have no blocks: by support alone, 1.25 for 1,000 weighted points.
  FramePlane parallel_search = face(-2.0, false, 0.0);
  parallel_search.blocks.clear();
  parallel_search.parallel = true;
  parallel_search.first_sight_points = 1000;
  const std::vector<FramePlane> planes{wall, mixing, small, face(1.0, true, 0.002), face(1.5, false, 0.002),
                                       face(-1.0, true, 0.02), near_wall, parallel_search};
  m.frame(planes, 0.1);
  const std::vector<FirstSight> expected{FirstSight::kKnownPlane,     FirstSight::kMixesSurfaces,
                                         FirstSight::kTooSmall,       FirstSight::kComplete,
                                         FirstSight::kNotFittingItsBlocks, FirstSight::kImprecise,
                                         FirstSight::kNearKnownPlane, FirstSight::kWithoutBlocks};
  ASSERT_EQ(m.map.lastFirstSights().size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i)
  {
    EXPECT_EQ(m.map.lastFirstSights()[i], expected[i])
        << "plane " << i << ": " << toString(m.map.lastFirstSights()[i]) << ", expected " << toString(expected[i]);
    if (i == 0) continue;
    EXPECT_EQ(matching(m.map.planes(), planes[i].normal).size(), expected[i] == FirstSight::kComplete ? 1u : 0u)
        << "plane " << i << " (" << toString(expected[i]) << ")";
  }
}

// A region that does not fit its blocks and is centred on a larger surface the same frame
// measured, turned less than a crease from it, is that surface bent by the sensor (osd-learn's
// table corners near the camera: 0.1-0.17 rad off, 3-5 mm from the table at their centroids): it
// does not vote. The same region 2 cm above the table (a lid), turned beyond a crease (a face
// rising from the table), or fitting its blocks is a surface of its own and reported at once;
// one within the merge tolerances (0.02 rad) votes for the table's plane.
TEST(PlaneMap, ARegionBentOffASurfaceTheFrameMeasuredIsPartOfIt)
{
  struct Case
  {
    double height, tilt;
    bool fits, reported;
  };
  for (const Case& c : {Case{0.003, 0.15, false, false}, Case{-0.004, 0.1, false, false}, Case{0.02, 0.15, false, true},
                        Case{0.003, 0.6, false, true}, Case{0.003, 0.15, true, true}, Case{0.003, 0.02, false, true}})
  {
    Map m;
    const FramePlane table = m.fitting(kFloor, Eigen::Vector3d(0.0, 1.0, 0.7), 150000);
    // 2,000 points 0.6 m away: weighted to the full first-sight bar.
    const Eigen::Vector3d tilted(0.0, std::sin(c.tilt), std::cos(c.tilt));
    FramePlane piece = m.fitting(tilted, Eigen::Vector3d(-0.3, 0.9, 0.7 + c.height), 2000);
    piece.first_sight_points = m.params.strong_support;
    piece.fits_its_blocks = c.fits;
    m.frame({table, piece}, 0.0);
    const std::string what = "height " + std::to_string(c.height) + " m, tilt " + std::to_string(c.tilt) +
                             " rad, fits " + std::to_string(c.fits);
    ASSERT_EQ(m.map.lastFirstSights().size(), 2u);
    EXPECT_EQ(m.map.lastFirstSights()[1] == FirstSight::kPartOfMeasuredSurface, !c.reported)
        << what << ": " << toString(m.map.lastFirstSights()[1]);
    EXPECT_EQ(matching(m.map.planes(), tilted).size(), c.reported ? 1u : 0u) << what;
    EXPECT_EQ(matching(m.map.planes(), kFloor).size(), 1u) << what;
  }
}

// Snapped new faces that took one known direction in one frame (a staircase's risers) measure
// it together: three risers each too imprecise alone (sigma 0.022 rad) are reported at first
// sight when their own normals agree with it and with each other, not one alone, not one whose
// only companion is a map plane measured again, not two whose own normals lie apart beyond
// their noise, and not four whose pooled normal refutes the known one.
TEST(PlaneMap, SnappedFacesSharingADirectionMeasureItTogether)
{
  const Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  const double sigma = 0.022;
  auto riser = [&](const Map& m, double x, double tilt, double own_sigma = 0.022) {
    FramePlane p = m.fitting(direction, Eigen::Vector3d(x, 0.0, 0.5), 3000, own_sigma);
    p.parallel = true;
    p.first_sight_points = 1000;  // by support alone 1.25, under global_threshold
    p.own_normal = Eigen::Vector3d(std::cos(tilt), std::sin(tilt), 0.0);
    p.own_normal_information =
        (Eigen::Matrix3d::Identity() - direction * direction.transpose()) / (own_sigma * own_sigma);
    return p;
  };
  auto firstSights = [](Map& m, const std::vector<FramePlane>& planes, double stamp) {
    m.frame(planes, stamp);
    return m.map.lastFirstSights();
  };
  {
    Map m;
    EXPECT_EQ(firstSights(m, {riser(m, 1.0, 0.01), riser(m, 1.3, -0.01), riser(m, 1.6, 0.0)}, 0.0),
              std::vector<FirstSight>(3, FirstSight::kComplete));
    EXPECT_EQ(matching(m.map.planes(), direction).size(), 3u);
  }
  {
    Map m;
    EXPECT_EQ(firstSights(m, {riser(m, 1.0, 0.01)}, 0.0), std::vector<FirstSight>{FirstSight::kImprecise});
    EXPECT_TRUE(m.map.planes().empty());
  }
  {
    Map m;
    const FramePlane wall = m.fitting(direction, Eigen::Vector3d(3.0, 0.0, 1.0), 20000);
    m.frame({wall}, 0.0);
    const FramePlane wall_again = riser(m, 3.0, 0.0, 0.002);
    EXPECT_EQ(firstSights(m, {wall_again, riser(m, 1.0, 0.01)}, 0.1),
              (std::vector<FirstSight>{FirstSight::kKnownPlane, FirstSight::kImprecise}));
  }
  {
    Map m;  // each 2.3 sigmas off the known normal, 3.2 sigmas of their difference apart
    EXPECT_EQ(firstSights(m, {riser(m, 1.0, 0.05), riser(m, 1.3, -0.05)}, 0.0),
              std::vector<FirstSight>(2, FirstSight::kImprecise));
  }
  {
    Map m;  // each 1.6 sigmas off, together 3.2 of their pooled sigma
    EXPECT_EQ(firstSights(m, {riser(m, 1.0, 0.035), riser(m, 1.3, 0.035), riser(m, 1.6, 0.035), riser(m, 1.9, 0.035)},
                          0.0),
              std::vector<FirstSight>(4, FirstSight::kImprecise));
  }
  EXPECT_GT(2.0 * M_SQRT2 * sigma, DetectorParams().merge_angle);  // imprecise alone
}

// A precise new face near a known plane waits for a second frame only when it could be that
// plane measured badly: turned 0.08 rad (under three merge angles) about a point on the known
// wall it waits; the same turn 20 cm in front of the wall and 3 m along it (offsets 3 cm apart
// at the world origin, 20 cm apart where it was measured) is another surface, reported at once.
TEST(PlaneMap, ANewFaceWaitsOnlyWhereAKnownPlanePassesItsPoints)
{
  const Eigen::Vector3d turned(std::cos(0.08), std::sin(0.08), 0.0);
  for (const Eigen::Vector3d& centroid : {Eigen::Vector3d(2.0, 0.0, 1.0), Eigen::Vector3d(1.8, 3.0, 1.0)})
  {
    const bool on_wall = centroid.x() == 2.0;
    Map m;
    const FramePlane wall = m.fitting(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(2.0, 0.0, 1.0), 20000);
    m.frame({wall}, 0.0);
    ASSERT_EQ(m.map.planes().size(), 1u);
    const FramePlane face = m.fitting(turned, centroid, 3000);
    m.frame({wall, face}, 0.1);
    EXPECT_EQ(matching(m.map.planes(), turned).size(), on_wall ? 0u : 1u)
        << "face centred at (" << centroid.transpose() << "), offset at the origin "
        << std::abs(face.d - wall.d) << " m from the wall's";
  }
}

// A precise new face that a known plane passes farther off than its offset noise and a face's
// warp allow (3 sqrt(1 mm^2 + 5 mm^2) = 15 mm) is another surface, reported at first sight: a
// shelf board 3.7 cm under a box top. Turned 0.08 rad with its points 1 cm off the box top it
// may be the box top measured badly, and waits.
TEST(PlaneMap, AFaceTheKnownPlaneMissesBeyondItsNoiseIsAnotherSurface)
{
  const Eigen::Vector3d turned(std::sin(0.08), 0.0, std::cos(0.08));
  struct Case
  {
    Eigen::Vector3d normal;
    double below;
    FirstSight expected;
  };
  for (const Case& c : {Case{kFloor, 0.037, FirstSight::kComplete}, Case{turned, 0.010, FirstSight::kNearKnownPlane}})
  {
    Map m;
    const FramePlane box_top = m.fitting(kFloor, Eigen::Vector3d(1.0, 0.0, 0.5), 20000);
    m.frame({box_top}, 0.0);
    const FramePlane board = m.fitting(c.normal, Eigen::Vector3d(1.3, 0.4, 0.5 - c.below), 3000);
    m.frame({box_top, board}, 0.1);
    ASSERT_EQ(m.map.lastFirstSights().size(), 2u);
    EXPECT_EQ(m.map.lastFirstSights()[1], c.expected)
        << c.below << " m under the box top: " << toString(m.map.lastFirstSights()[1]);
    EXPECT_EQ(matching(m.map.planes(), c.normal).size() - (c.normal == kFloor ? 1u : 0u),
              c.expected == FirstSight::kComplete ? 1u : 0u);
  }
}

// A region whose blocks lie off its plane beyond their noise (FramePlane::mixes_surfaces: two
// box faces a few degrees apart grown as one) does not vote, however many points it has and
// however often a still camera measures it again; the same region with its blocks on its plane
// is reported from one frame.
TEST(PlaneMap, ARegionMixingSurfacesDoesNotVote)
{
  for (bool mixes : {false, true})
  {
    Map m;
    FramePlane faces = m.plane(Eigen::Vector3d(1, 0, 0), -2.0, 20000, 2.0 * m.params.strong_support);
    faces.blocks = {1, 2, 3};
    faces.mixes_surfaces = mixes;
    for (int f = 0; f < 5; ++f)
    {
      m.frame({faces}, 0.1 * f);
      EXPECT_EQ(m.map.planes().size(), mixes ? 0u : 1u) << "mixes surfaces " << mixes << ", frame " << f;
    }
  }
}

// A plane one frame reported that the next frame does not measure again, while that frame
// measures a plane of at least its support within three merge tolerances of it, was that
// surface measured badly: the better measurement replaces it. A weaker nearby plane does not.
TEST(PlaneMap, AOneFramePlaneMeasuredAgainNearbyByABetterMeasurementIsReplaced)
{
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(0.08, Eigen::Vector3d::UnitX()) * kFloor;  // 1.6 merge_angle
  for (double later_support : {20000.0, 4000.0})
  {
    Map m;
    m.params.forgetting = kForgetByThinning;  // a plane not measured again keeps 2 - thinning_rate
    m.frame({m.plane(kFloor, 1.0, 16000)}, 0.0);
    ASSERT_EQ(m.map.planes().size(), 1u);
    FrameData frame;
    m.map.observe({16000}, {}, frame, 0.0);
    m.frame({m.plane(tilted, 1.0, later_support)}, 1.0);
    const bool better = later_support >= 16000;
    EXPECT_EQ(matching(m.map.planes(), kFloor).size(), better ? 0u : 1u) << "later support " << later_support;
    EXPECT_EQ(matching(m.map.planes(), tilted).size(), better ? 1u : 0u) << "later support " << later_support;
  }
}

// A far wall's first measurement, turned 0.06 rad (over merge_angle, under three) about its
// points 2 m along the wall, was reported at first sight; at the world origin its offset lies
// 12 cm off the wall's (over three merge distances). The next frame measures the wall itself,
// better supported and precise, through the same points: the turned plane was the wall
// measured badly and is replaced, and the wall is reported in that frame, since the plane it
// would otherwise wait for is the one it replaced.
TEST(PlaneMap, ATurnedOneFramePlaneIsReplacedWhereTheBetterMeasurementPassesItsPoints)
{
  const Eigen::Vector3d centroid(3.0, 2.0, 1.0);
  const Eigen::Vector3d turned(std::cos(0.06), std::sin(0.06), 0.0);
  const Eigen::Vector3d wall = Eigen::Vector3d::UnitX();
  Map m;
  m.params.forgetting = kForgetByThinning;  // not measured again, it would keep 2 - thinning_rate
  auto measurement = [&](const Eigen::Vector3d& normal, double support, double normal_sigma) {
    FramePlane p = m.plane(normal, -normal.dot(centroid), support);
    p.fits_its_blocks = true;
    p.normal_sigma = normal_sigma;
    p.offset_sigma = 0.001;
    p.centroid = centroid;
    return p;
  };
  const FramePlane first = measurement(turned, 3000, 0.015);
  ASSERT_GT(std::abs(first.d - (-3.0)), 3.0 * m.params.merge_distance);  // apart at the origin
  m.frame({first}, 0.0);
  ASSERT_EQ(matching(m.map.planes(), turned).size(), 1u);
  FrameData frame;
  m.map.observe({3000}, {}, frame, 0.0);
  m.frame({measurement(wall, 6000, 0.005)}, 0.1);
  EXPECT_EQ(matching(m.map.planes(), turned).size(), 0u);
  ASSERT_EQ(matching(m.map.planes(), wall).size(), 1u);
  EXPECT_NEAR(std::abs(matching(m.map.planes(), wall)[0]->d), 3.0, 0.005);
}

// A box front 40 cm before a wall, snapped each frame to the wall's normal (x), while its own
// blocks fit a normal 0.035 rad off it: each frame's tilt has chi^2 4, under the snap's bar
// (9.21), but four viewpoints refute the wall's normal (p = 0.001) and the plane moves to its
// own normal through its centroids, keeping its id. A still camera repeats its error and
// refutes nothing; tilts that scatter either side of the normal refute nothing either. The
// pooled tilts are part of the map file: a restored map moves the plane in the same frame.
TEST(PlaneMap, SnappedMeasurementsWhoseOwnNormalsAgreeElsewhereMoveThePlaneThere)
{
  const Eigen::Vector3d wall = Eigen::Vector3d::UnitX();
  const double tilt = 0.035;
  const double information = 4.0 / (tilt * tilt);  // per frame, about both axes across the normal
  auto front = [&](const Map& m, double signed_tilt) {
    FramePlane p = m.plane(wall, -2.6, 9000);
    p.parallel = true;
    p.centroid = Eigen::Vector3d(2.6, 0.5, 1.0);
    p.own_normal = Eigen::AngleAxisd(signed_tilt, Eigen::Vector3d::UnitZ()) * wall;
    p.own_normal_information = information * (Eigen::Matrix3d::Identity() - wall * wall.transpose());
    return p;
  };
  const Eigen::Vector3d own = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitZ()) * wall;
  auto camera = [](int f) { return Eigen::Vector3d(0.0, 0.1 * f, 1.2); };  // 10 cm per frame, 2.6 m away
  auto frontPlane = [&](const Map& m) -> const DetectedPlane* {
    for (const DetectedPlane& p : m.map.planes())
      if (std::abs(p.d + 2.6 * p.normal.x()) < 0.05 && std::abs(p.normal.x()) > 0.99) return &p;
    return nullptr;
  };

  Map moving;
  Map restored;
  int front_id = -1;
  for (int f = 0; f < 4; ++f)
  {
    moving.frame({moving.plane(wall, -3.0, 40000), front(moving, tilt)}, f, camera(f));
    const DetectedPlane* plane = frontPlane(moving);
    ASSERT_NE(plane, nullptr) << "frame " << f;
    if (f == 0) front_id = plane->id;
    EXPECT_EQ(plane->id, front_id) << "frame " << f;
    if (f == 2)
    {
      std::string error;
      ASSERT_TRUE(restored.map.deserialize(moving.map.serialize(), &error)) << error;
    }
    if (f < 3)
    {
      EXPECT_GT(std::abs(plane->normal.dot(wall)), std::cos(1e-3)) << "frame " << f << ": refuted too early";
    }
  }
  const DetectedPlane* moved = frontPlane(moving);
  EXPECT_LT(unsignedAngle(moved->normal, own), 0.005) << "four viewpoints refute the wall's normal";
  EXPECT_NEAR(moved->normal.dot(Eigen::Vector3d(2.6, 0.5, 1.0)) + moved->d, 0.0, 0.01) << "through its centroids";
  ASSERT_EQ(moving.map.planes().size(), 2u);
  for (const DetectedPlane& p : moving.map.planes())
  {
    if (&p != moved)
    {
      EXPECT_GT(std::abs(p.normal.dot(wall)), std::cos(1e-3)) << "the wall keeps its normal";
    }
  }
  restored.frame({restored.plane(wall, -3.0, 40000), front(restored, tilt)}, 3, camera(3));
  EXPECT_EQ(restored.map.serialize(), moving.map.serialize());

  Map still;
  Map scattered;
  for (int f = 0; f < 8; ++f)
  {
    still.frame({still.plane(wall, -3.0, 40000), front(still, tilt)}, f, camera(0));
    scattered.frame({scattered.plane(wall, -3.0, 40000), front(scattered, f % 2 ? tilt : -tilt)}, f, camera(f));
  }
  for (const Map* m : {&still, &scattered})
  {
    const DetectedPlane* plane = frontPlane(*m);
    ASSERT_NE(plane, nullptr);
    EXPECT_GT(std::abs(plane->normal.dot(wall)), std::cos(1e-3)) << (m == &still ? "still camera" : "scattered tilts");
  }
}

TEST(PlaneMap, SerialisesToItselfExactly)
{
  Map m;
  for (int f = 0; f < 4; ++f)
    m.frame({m.plane(kFloor, 1.0, 20000), m.plane(Eigen::Vector3d(0.6, 0.8, 0), -2.5, 9000)}, f);
  const std::string bytes = m.map.serialize();
  Map restored;
  std::string error;
  ASSERT_TRUE(restored.map.deserialize(bytes, &error)) << error;
  EXPECT_EQ(restored.map.serialize(), bytes);
  ASSERT_EQ(restored.map.planes().size(), m.map.planes().size());
  // The restored map goes on exactly as the original.
  m.frame({m.plane(kFloor, 1.0, 20000)}, 4);
  restored.frame({restored.plane(kFloor, 1.0, 20000)}, 4);
  EXPECT_EQ(restored.map.serialize(), m.map.serialize());
  // A changed byte is refused and leaves the map as it was.
  std::string broken = bytes;
  broken[broken.size() / 2] ^= 0x10;
  EXPECT_FALSE(restored.map.deserialize(broken, &error));
  EXPECT_NE(error.find("checksum"), std::string::npos) << error;
  EXPECT_EQ(restored.map.serialize(), m.map.serialize());
  // How the last frame voted belongs to that frame, not to a map loaded after it.
  ASSERT_EQ(restored.map.lastFirstSights().size(), 1u);
  ASSERT_TRUE(restored.map.deserialize(bytes, &error)) << error;
  EXPECT_TRUE(restored.map.lastFirstSights().empty());
}
