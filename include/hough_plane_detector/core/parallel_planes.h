// Planes parallel to a known one (a stair's treads and risers, shelf boards): too narrow for
// a window of their own, so they raise no Hough peak; along a known normal a block's offset is
// precise even where its own normal is noise, so the free blocks' offsets are searched for
// clusters (a 1-D Hough transform per known direction).
#pragma once

#include <vector>

#include "hough_plane_detector/core/detected_plane.h"
#include "hough_plane_detector/core/frame_planes.h"

namespace hough_plane_detector
{

// Directions come from this frame's `planes` and the map's; each accepted cluster is
// appended to `planes` (parallel = true) and claims its blocks; every cluster tried is a
// candidate. Does nothing when parallel_support is 0.
void findParallelPlanes(const DetectorParams& params, const HoughParameterization& param, FrameData& frame,
                        const PlanarityTests& tests, const std::vector<DetectedPlane>& map_planes,
                        std::vector<FramePlane>& planes, std::vector<PlaneCandidate>& candidates);

}  // namespace hough_plane_detector
