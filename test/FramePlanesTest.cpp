// The per-frame fits from Hough peaks (windows and block regions) on a rendered frame.
#include <gtest/gtest.h>

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
