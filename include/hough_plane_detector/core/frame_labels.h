// Which of the frame's windows, blocks and pixels lie on which map plane, and so each map
// plane's measured support in the frame.
#pragma once

#include <vector>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/detected_plane.h"
#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/frame_data.h"
#include "hough_plane_detector/core/frame_planes.h"

namespace hough_plane_detector
{

struct FrameLabels
{
  std::vector<int> samples;  // plane id of each planar window of frame.samples (-1: none)
  std::vector<int> blocks;   // plane id of each block of the frame's grid (-1: none)
  std::vector<int> support;  // points of the frame on each map plane (index of the plane list)
};

// Windows go to the map plane they agree with (support_angle, support_distance). With block
// regions, each accepted region of the frame labels its blocks with the map plane it is (its
// points are the support, also where a face is too small for a window); every other plane
// takes its windows' blocks that lie on it.
void labelFrame(const DetectorParams& params, FrameData& frame, FramePlaneFitter& fitter,
                const std::vector<FramePlane>& frame_planes, const std::vector<DetectedPlane>& planes,
                FrameLabels& labels);

// Plane id of every pixel (-1: none): pixels of a labelled block within support_distance of
// its plane, and, spreading from those blocks into unlabelled neighbours (on from a block whose
// points lie mostly so), pixels within 3 sigma of the sensor's depth noise of the plane: the
// blocks a region's noise tests left out. `cloud` must be the frame's cloud; nothing is
// labelled when its grid differs.
void labelPixels(const CloudView& cloud, const FrameData& frame, const std::vector<int>& block_labels,
                 const std::vector<DetectedPlane>& planes, const DetectorParams& params, std::vector<int>& labels);

}  // namespace hough_plane_detector
