#include "hough_plane_detector/core/detector_params.h"

#include <cmath>
#include <sstream>

namespace hough_plane_detector
{

namespace
{
constexpr double kPi = 3.14159265358979323846;
}

double DetectorParams::effectiveAngleStep() const
{
  // Paper Table 2: the presets split [-pi, pi] into `resolution` cells.
  return resolution > 0 ? 2.0 * kPi / resolution : angle_step;
}

double DetectorParams::effectiveDStep() const
{
  // Paper Table 2: 19.5 mm at 512, 9.7 mm at 1024, 4.8 mm at 2048 (10 m / resolution).
  return resolution > 0 ? 10.0 / resolution : d_step;
}

bool DetectorParams::validate(std::string* error) const
{
  std::ostringstream err;
  if (resolution != 0 && resolution != 256 && resolution != 512 && resolution != 1024 && resolution != 2048)
    err << "resolution must be 0 (custom), 256, 512, 1024 or 2048, got " << resolution << "; ";
  if (!(effectiveAngleStep() >= 0.0005 && effectiveAngleStep() <= 0.2))
    err << "angle_step must be in [0.0005, 0.2] rad, got " << effectiveAngleStep() << "; ";
  if (!(effectiveDStep() >= 0.001 && effectiveDStep() <= 0.5))
    err << "d_step must be in [0.001, 0.5] m, got " << effectiveDStep() << "; ";
  if (!(max_distance > 0.1 && max_distance <= 1000.0))
    err << "max_distance must be in (0.1, 1000] m, got " << max_distance << "; ";
  if (!(blur_sigma > 0.1 && blur_sigma <= 5.0)) err << "blur_sigma must be in (0.1, 5] cells, got " << blur_sigma << "; ";
  if (blur_kernel_size < 1 || blur_kernel_size > 15 || blur_kernel_size % 2 == 0)
    err << "blur_kernel_size must be odd and in [1, 15], got " << blur_kernel_size << "; ";
  if (peak_window < 3 || peak_window > 9 || peak_window % 2 == 0)
    err << "peak_window must be odd and in [3, 9], got " << peak_window << "; ";
  if (!(local_threshold > 0.0)) err << "local_threshold must be > 0, got " << local_threshold << "; ";
  if (min_support < 0) err << "min_support must be >= 0, got " << min_support << "; ";
  if (!(global_threshold > 0.0)) err << "global_threshold must be > 0, got " << global_threshold << "; ";
  if (!(thinning_rate >= 0.0 && thinning_rate < 1.0))
    err << "thinning_rate must be in [0, 1), got " << thinning_rate << "; ";
  if (!(permanence_cap > global_threshold))
    err << "permanence_cap (" << permanence_cap << ") must exceed global_threshold (" << global_threshold << "); ";
  if (strong_support < 0) err << "strong_support must be >= 0, got " << strong_support << "; ";
  if (max_chunks < 16) err << "max_chunks must be >= 16, got " << max_chunks << "; ";
  if (!(merge_angle >= 0.0 && merge_angle < 0.5)) err << "merge_angle must be in [0, 0.5) rad, got " << merge_angle << "; ";
  if (!(merge_distance >= 0.0 && merge_distance < 1.0))
    err << "merge_distance must be in [0, 1) m, got " << merge_distance << "; ";
  if (normal_window < 2 || normal_window > 64) err << "normal_window must be in [2, 64], got " << normal_window << "; ";
  if (normal_stride < 1 || normal_stride > normal_window || (normal_stride > 0 && normal_window % normal_stride != 0))
    err << "normal_window (" << normal_window << ") must be a multiple of normal_stride (" << normal_stride << "); ";
  if (!(min_valid_fraction > 0.0 && min_valid_fraction <= 1.0))
    err << "min_valid_fraction must be in (0, 1], got " << min_valid_fraction << "; ";
  if (!(max_curvature > 0.0 && max_curvature <= 1.0 / 3.0))
    err << "max_curvature must be in (0, 1/3], got " << max_curvature << "; ";
  if (max_window_scale != 1 && max_window_scale != 2 && max_window_scale != 4)
    err << "max_window_scale must be 1, 2 or 4, got " << max_window_scale << "; ";
  if (!(sensor_noise >= 0.0 && sensor_noise <= 10.0)) err << "sensor_noise must be in [0, 10], got " << sensor_noise << "; ";
  if (sensor_model < 0 || sensor_model > 3)
    err << "sensor_model must be 0 (kinect_v1), 1 (xtion), 2 (realsense_d400) or 3 (tof), got " << sensor_model << "; ";
  if (!(support_distance > 0.0)) err << "support_distance must be > 0, got " << support_distance << "; ";
  if (!(support_angle > 0.0 && support_angle < 1.5)) err << "support_angle must be in (0, 1.5) rad, got " << support_angle << "; ";
  if (parallel_support < 0) err << "parallel_support must be >= 0, got " << parallel_support << "; ";
  if (!(snap_angle >= 0.0 && snap_angle < 0.5)) err << "snap_angle must be in [0, 0.5) rad, got " << snap_angle << "; ";
  if (world_z_up != 0 && world_z_up != 1) err << "world_z_up must be 0 or 1, got " << world_z_up << "; ";
  if (region_growing != 0 && region_growing != 1) err << "region_growing must be 0 or 1, got " << region_growing << "; ";
  if (measurement_threads < 1 || measurement_threads > 8)
    err << "measurement_threads must be in [1, 8], got " << measurement_threads << "; ";
  if (forgetting != 0 && forgetting != 1) err << "forgetting must be 0 (thinning) or 1 (evidence), got " << forgetting << "; ";
  std::string s = err.str();
  if (s.empty()) return true;
  s.resize(s.size() - 2);
  if (error) *error = s;
  return false;
}

}  // namespace hough_plane_detector
