// Organized points from a depth image (16-bit millimetres as OpenNI2 gives them, or metres).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "hough_plane_detector/core/camera_intrinsics.h"

namespace hough_plane_detector
{

// Points in the camera optical frame (x right, y down, z forward), 3 floats per pixel, row by
// row; NaN where the depth is 0 or outside [min_range, max_range]. row_stride in bytes.
void depthImageToPoints(const uint16_t* depth, int width, int height, size_t row_stride,
                        const CameraIntrinsics& intrinsics, double metres_per_unit, std::vector<float>& points);

// The same from depths in metres (32FC1), NaN or 0 for no return.
void depthImageToPoints(const float* metres, int width, int height, size_t row_stride, const CameraIntrinsics& intrinsics,
                        std::vector<float>& points);

// A Kinect v1's raw 11-bit disparity (libfreenect's FREENECT_DEPTH_11BIT, the only mode
// fakenect plays) as depth by the sensor's nominal calibration, z = 1 / (3.3309495 -
// 0.0030711016 raw) m (N. Burrus' fit): 0 for no return (2047) and for values no depth in
// [min_range, max_range] gives (a truncated frame's zeros).
uint16_t kinectDisparityToMillimetres(uint16_t raw, const CameraIntrinsics& intrinsics);
// The inverse, for recordings of rendered depths: the nearest raw disparity, 2047 for no return.
uint16_t kinectMetresToDisparity(double metres);

// Pinhole intrinsics of a sensor from its image size and fields of view (radians).
CameraIntrinsics intrinsicsFromFieldOfView(int width, int height, double horizontal_fov, double vertical_fov);

}  // namespace hough_plane_detector
