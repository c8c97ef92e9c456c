// The frame's labels (frame_labels): which map plane each block, window and pixel of the frame
// lies on, and each plane's support, on a rendered frame seen by the whole detector.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

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

// A region's noise tests leave out blocks whose points still lie on its plane (a real sensor's
// correlated errors put their centroids off it); the pixel labels, which ~inliers and
// ~segmented_cloud publish, spread to them from the plane's blocks, and stop at surfaces off it.
TEST(FrameLabels, APlanesPixelLabelSpreadsIntoBlocksItsRegionLeftOutAndStopsAtSurfacesOffIt)
{
  Frame f;
  const int floor_index = f.truePlane("floor");
  const TruePlane& floor = f.renderer.truePlanes()[floor_index];
  DetectedPlane floor_plane;
  floor_plane.id = 7;
  floor_plane.normal = floor.normal;
  floor_plane.d = floor.d;
  // The floor's blocks carry its id, but for a 3 x 3 hole in the middle of them.
  std::vector<int> block_labels(f.frame.blocks.size(), -1);
  for (int b : f.blocksOn(floor_index)) block_labels[b] = floor_plane.id;
  const std::vector<int> hole = f.squareOn("floor", 3);
  ASSERT_EQ(hole.size(), 9u);
  for (int b : hole) block_labels[b] = -1;

  std::vector<int> labels;
  labelPixels(f.rendered.view(), f.frame, block_labels, {floor_plane}, f.params, labels);
  ASSERT_EQ(labels.size(), f.rendered.pixel_plane.size());
  const int s = blockSize(f.params.normal_window, f.params.normal_stride), bx_count = f.frame.blocksX();
  int hole_pixels = 0, hole_labelled = 0;
  for (int b : hole)
    for (int v = b / bx_count * s; v < (b / bx_count + 1) * s; ++v)
      for (int u = b % bx_count * s; u < (b % bx_count + 1) * s; ++u)
      {
        ++hole_pixels;
        hole_labelled += labels[static_cast<size_t>(v) * f.rendered.width + u] == floor_plane.id;
      }
  EXPECT_GE(hole_labelled, 0.95 * hole_pixels);
  // The spread reaches every floor pixel. Off the floor it labels only what lies within the
  // depth noise of the floor (3 sigma: 2-3 cm at the step's 2 m, 3-4 cm at the wall's 3.7 m),
  // a foot of each surface that meets it; the step's top, 20 cm up, not a pixel.
  std::vector<int> pixels(f.renderer.truePlanes().size() + 1, 0), floor_labelled(pixels.size(), 0);
  for (size_t i = 0; i < labels.size(); ++i)
  {
    if (!std::isfinite(f.rendered.xyz[3 * i + 2])) continue;
    const size_t surface = f.rendered.pixel_plane[i] < 0 ? pixels.size() - 1 : f.rendered.pixel_plane[i];
    ++pixels[surface];
    floor_labelled[surface] += labels[i] == floor_plane.id;
  }
  EXPECT_GE(floor_labelled[floor_index], 0.97 * pixels[floor_index]);
  for (size_t k = 0; k + 1 < pixels.size(); ++k)
  {
    const std::string& name = f.renderer.truePlanes()[k].name;
    if (static_cast<int>(k) == floor_index || pixels[k] == 0) continue;
    EXPECT_LE(floor_labelled[k], (name == "step_top" ? 0.0 : name == "wall" ? 0.05 : 0.25) * pixels[k]) << name;
  }
  EXPECT_LE(floor_labelled.back(), 0.05 * pixels.back()) << "the pillar";
}
