// Every tuning knob of the detector. Names equal the CLI flags and the ROS parameter names.
#pragma once

#include <string>

// Every parameter as X(type, name), in one place: the CLI flags, the nodelet's ROS parameters
// and its dynamic_reconfigure config are all generated from this list.
#define HOUGH_PLANE_DETECTOR_PARAMS(X) \
  X(int, resolution)                   \
  X(double, angle_step)                \
  X(double, d_step)                    \
  X(double, max_distance)              \
  X(double, blur_sigma)                \
  X(int, blur_kernel_size)             \
  X(int, peak_window)                  \
  X(double, local_threshold)           \
  X(int, min_support)                  \
  X(double, global_threshold)          \
  X(int, strong_support)               \
  X(double, thinning_rate)             \
  X(double, permanence_cap)            \
  X(int, max_chunks)                   \
  X(double, merge_angle)               \
  X(double, merge_distance)            \
  X(int, normal_window)                \
  X(int, normal_stride)                \
  X(double, min_valid_fraction)        \
  X(double, max_curvature)             \
  X(int, max_window_scale)             \
  X(double, sensor_noise)              \
  X(int, sensor_model)                 \
  X(double, support_distance)          \
  X(double, support_angle)             \
  X(int, parallel_support)             \
  X(double, snap_angle)                \
  X(int, world_z_up)                   \
  X(int, region_growing)               \
  X(int, forgetting)                   \
  X(int, measurement_threads)

namespace hough_plane_detector
{

constexpr int kForgetByThinning = 0;
constexpr double kStrongSupportDepth = 2.0;  // m: nearer points count more toward strong_support
constexpr int kForgetByEvidence = 1;

struct DetectorParams
{
  // Hough-space resolution preset (paper Table 2): 256, 512, 1024, 2048; 0 = use angle_step/d_step.
  int resolution = 1024;
  // Angle step of the (alpha, beta) axes in radians when resolution == 0.
  double angle_step = 0.0061;
  // Step of the d axis in metres when resolution == 0.
  double d_step = 0.0097;
  // |d| range of the world-frame Hough space in metres; planes farther from the origin are ignored.
  double max_distance = 100.0;

  // Gaussian blur of the per-frame space and of each global contribution, in cells.
  double blur_sigma = 1.0;
  // Odd edge length of the precomputed blur kernel, in cells.
  int blur_kernel_size = 5;
  // Odd edge length of the sliding window for peaks and their sub-voxel mean (eq. 6), in cells.
  int peak_window = 5;

  // Minimum blurred value of a local (per-frame) peak; roughly points voting for one cell.
  double local_threshold = 500.0;
  // Minimum number of points in the frame that lie on a local peak's plane for it to be kept.
  int min_support = 800;
  // Minimum global value (about the number of frames that saw the plane) to report a plane.
  double global_threshold = 1.5;
  // A per-frame plane not yet in the map adds 1 + min(1, points / (strong_support *
  // max(1, sensor_noise)^2)) to the global space, so one this well supported is reported at
  // first sight; planes in the map, and all with 0, add 1 (the paper). A point nearer than
  // kStrongSupportDepth counts (sigma there / sigma at its depth)^2: near the sensor one
  // frame's tests see the folds and bends noise hides farther away. A plane of under
  // 2 min_support points needs a second frame (too small for the curvature tests), unless it is
  // parallel to a known plane and its weighted points reach strong_support itself. That test
  // pools points and support over the frame's planes within the merge tolerances of each other
  // (one surface grown as two regions); the weight added is each plane's own.
  int strong_support = 16000;
  // Amount every global cell loses per frame (paper 3.7: 0.01 - 0.1).
  double thinning_rate = 0.05;
  // Global cells reaching this value become permanent and stop thinning.
  double permanence_cap = 20.0;
  // Most 16^3 chunks (16 kB each) the global space may hold; beyond it the weakest are freed.
  int max_chunks = 8192;

  // Planes closer than both merge thresholds are one plane (eq. 7-10). Three d cells of the
  // 1024 preset: the nearest the 5-cell peak window resolves, and box faces 3 cm apart (two
  // stacked boxes, a lid and a front) stay two planes.
  double merge_angle = 0.05;
  double merge_distance = 0.03;

  // Normal estimation: square window and stride in pixels; window must be a multiple of stride.
  int normal_window = 32;
  int normal_stride = 16;
  // Fraction of a window's pixels that must be valid for a normal.
  double min_valid_fraction = 0.6;
  // Windows whose curvature (smallest eigenvalue / trace) exceeds this are not planar.
  double max_curvature = 0.02;
  // A window whose noise is as thick as half its width (far from a Kinect) is measured again
  // over 2x, then 4x, as wide a window around it, up to this factor: 1 (never), 2 or 4.
  int max_window_scale = 4;
  // C_noc of eq. 11 assumed for the sensor (for sensor models other than the structured-light
  // ones, a scale on their published noise curve): windows as rough as its noise still count as
  // planar; 0 leaves only the curvature test.
  double sensor_noise = 1.0;
  // Depth noise curve (core/sensor_model.h): 0 kinect_v1, 1 xtion, 2 realsense_d400, 3 tof.
  // The focal length it needs comes from each cloud itself.
  int sensor_model = 0;

  // A window supports a plane when its centroid is this close (m) and its normal this close (rad).
  double support_distance = 0.05;
  double support_angle = 0.2;
  // Points a plane parallel to one already found (a stair tread, a shelf) needs to be found
  // among the blocks no Hough peak took, with the known normal; 0 turns that search off.
  int parallel_support = 800;
  // A per-frame plane within this angle (rad) of a known plane's normal takes that normal when
  // most of its points lie on the parallel plane within their noise (a far stair tread leaning
  // on its edges); 0 never.
  double snap_angle = 0.1;
  // 1: the world frame's +z points up (REP 103: odom, map). A region (or a parallel-search
  // cluster) then takes a known normal more than 26 deg off the vertical only if its points'
  // own scatter, not just the noise model, cannot tell the two apart (an F test): level
  // surfaces are parallel by gravity, box faces at any yaw only by chance; and a region whose
  // points cannot orient it may be kept upright (FramePlaneFitter::uprightFace). 0: up is
  // unknown (a PCD in its camera's frame), every snap is judged by the noise model alone.
  int world_z_up = 1;
  // Per-frame planes: 1 = each Hough peak seeds regions of 8 x 8 pixel blocks grown while they
  // lie on the refitted plane within the sensor's noise, then the flat blocks left seed regions
  // of their own (small faces that raise no peak); 0 = each peak takes the windows that agree
  // with it (the paper).
  int region_growing = 1;
  // How the map forgets: 1 = by evidence (a plane out of view keeps its state; one whose
  // extent the frames show to be gone leaves within about ten frames; core/plane_evidence.h),
  // 0 = thinning (paper 3.7: every cell loses thinning_rate per frame; Fig. 6-8 use it).
  int forgetting = 1;
  // Threads that measure a frame's blocks and windows (the calling one and measurement_threads - 1
  // helpers, 1 to 8); the planes found do not depend on it.
  int measurement_threads = 2;

  // True when the combination is valid; otherwise false, with what is wrong in `error`.
  bool validate(std::string* error = nullptr) const;
  // Angle and d steps after applying the preset.
  double effectiveAngleStep() const;
  double effectiveDStep() const;
};

// The defaults for clouds in their camera's own frame (a PCD file alone): up is unknown.
inline DetectorParams cameraFrameDefaults()
{
  DetectorParams params;
  params.world_z_up = 0;
  return params;
}

}  // namespace hough_plane_detector
