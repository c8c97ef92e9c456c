// The frame's labels (frame_labels): which map plane each block, window and pixel of the frame
// lies on, and each plane's support, on a rendered frame seen by the whole detector.
#include <gtest/gtest.h>

#include <cmath>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/plane_metrics.h"
#include "frame_fixture.h"

using namespace hough_plane_detector;
using namespace hough_plane_detector::test;

TEST(FrameLabels, BlocksAndPixelsOfTheWallCarryItsIdAndThePillarsNone)
{
  Frame f;
  PlaneDetector detector(f.params);
  for (int i = 0; i < 3; ++i)
    ASSERT_TRUE(detector.processFrame(f.rendered.view(), f.rendered.camera_to_world, 0.1 * i));
  const int wall_index = f.truePlane("wall");
  const TruePlane& wall = f.renderer.truePlanes()[wall_index];
  int wall_id = -1, wall_support = 0;
  for (const DetectedPlane& p : detector.planes())
    if (angleError(p.normal, wall.normal) < 0.02 && distanceError(p.normal, p.d, wall.normal, wall.d) < 0.03)
    {
      wall_id = p.id;
      wall_support = p.support;
    }
  ASSERT_GE(wall_id, 0) << "the wall is not in the map";

  const std::vector<int>& block_labels = detector.lastBlockLabels();
  ASSERT_EQ(block_labels.size(), f.frame.blocks.size());
  const std::vector<int> wall_blocks = f.blocksOn(wall_index), pillar_blocks = f.blocksOn(-1);
  int wall_labelled = 0, pillar_labelled = 0;
  for (int b : wall_blocks) wall_labelled += block_labels[b] == wall_id;
  for (int b : pillar_blocks) pillar_labelled += block_labels[b] >= 0;
  EXPECT_GE(wall_labelled, 0.9 * wall_blocks.size());
  EXPECT_EQ(pillar_labelled, 0);

  // Pixels labelled with the wall's id are the wall's, and there are about as many as its support.
  std::vector<int> pixel_labels;
  detector.labelPixels(f.rendered.view(), pixel_labels);
  ASSERT_EQ(pixel_labels.size(), f.rendered.pixel_plane.size());
  int labelled = 0, on_wall = 0;
  for (size_t i = 0; i < pixel_labels.size(); ++i)
  {
    if (pixel_labels[i] != wall_id) continue;
    ++labelled;
    on_wall += f.rendered.pixel_plane[i] == wall_index;
  }
  EXPECT_GE(on_wall, 0.97 * labelled);
  EXPECT_GT(labelled, 0.8 * wall_support);
  EXPECT_LT(labelled, 1.2 * wall_support);
}
