#include "hough_plane_detector/core/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace hough_plane_detector
{

namespace
{
constexpr const char* kNames[kSensorModelCount] = {"kinect_v1", "xtion", "realsense_d400", "tof"};
constexpr double kStructuredLightBaseline = 0.075;  // m, Kinect v1 and Xtion
constexpr double kStructuredLightSubpixel = 8.0;     // disparity in 1/8 pixel steps
constexpr double kD400Baseline = 0.050;              // m, D435 (D415: 55 mm)
constexpr double kD400SubpixelRms = 0.08;            // px, Intel's typical RMS subpixel error
constexpr int kReferenceWidth = 640;
}  // namespace

const char* sensorModelName(int model)
{
  return model >= 0 && model < kSensorModelCount ? kNames[model] : "unknown";
}

bool parseSensorModel(const std::string& text, int* model)
{
  for (int m = 0; m < kSensorModelCount; ++m)
    if (text == kNames[m] || text == std::to_string(m))
    {
      *model = m;
      return true;
    }
  return false;
}

double structuredLightSigma(double depth, double coefficient)
{
  const double z_mm = depth * 1000.0;  // eq. 11 works in millimetres
  return std::max(0.0, 2.6610e-6 * z_mm * z_mm * coefficient * coefficient - 1.0787e-3 * z_mm * coefficient + 2.7011) /
         1000.0;
}

double nominalFocalLength(int model)
{
  switch (model)
  {
    case kXtion: return 570.3;
    case kRealsenseD400: return 385.0;  // D435 depth at 640 x 480
    case kTof: return 365.0 * kReferenceWidth / 512.0;  // Kinect v2, 512 px wide
    default: return 580.0;
  }
}

DepthNoiseModel::DepthNoiseModel(int model, double coefficient, double focal_px)
  : model_(model), coefficient_(coefficient), focal_px_(focal_px > 0.0 ? focal_px : nominalFocalLength(model))
{
  // Asked thousands of times a frame (every block, window and extent cell).
  sigma_table_.resize(kTableSize);
  for (int i = 0; i < kTableSize; ++i) sigma_table_[i] = computeSigma(static_cast<double>(i) / kTableStepsPerMetre);
}

double DepthNoiseModel::quantizationStep(double depth) const
{
  if (!enabled() || (model_ != kKinectV1 && model_ != kXtion)) return 0.0;
  return depth * depth / (focal_px_ * kStructuredLightBaseline * kStructuredLightSubpixel);
}

double DepthNoiseModel::computeSigma(double depth) const
{
  if (!enabled()) return 0.0;
  double random = 0.0;
  switch (model_)
  {
    case kRealsenseD400:
      random = coefficient_ * depth * depth * kD400SubpixelRms / (focal_px_ * kD400Baseline);
      break;
    case kTof:
      random = coefficient_ * (1.5 - 0.5 * depth + 0.3 * depth * depth) / 1000.0;
      break;
    default:
      random = structuredLightSigma(depth, coefficient_);
  }
  // A uniform step has standard deviation step / sqrt(12).
  const double step = quantizationStep(depth);
  return std::sqrt(random * random + step * step / 12.0);
}

namespace
{
// Least-squares line ratio = slope * pixel + intercept; false when it is no such line.
struct LineFit
{
  double n = 0, sp = 0, sr = 0, spp = 0, spr = 0, srr = 0;
  void add(double pixel, double ratio)
  {
    n += 1;
    sp += pixel;
    sr += ratio;
    spp += pixel * pixel;
    spr += pixel * ratio;
    srr += ratio * ratio;
  }
  // focal = 1 / slope, centre = -intercept / slope.
  bool solve(double* focal, double* centre) const
  {
    constexpr double kMinPoints = 100;
    if (n < kMinPoints) return false;
    const double var_p = spp / n - (sp / n) * (sp / n);
    if (!(var_p > 0.0)) return false;
    const double slope = (spr / n - (sp / n) * (sr / n)) / var_p;
    if (!(slope > 0.0)) return false;
    // Residual of the line in pixels: a cloud that is no pinhole projection has no focal length.
    const double var_r = srr / n - (sr / n) * (sr / n);
    const double residual_px = std::sqrt(std::max(0.0, var_r - slope * slope * var_p)) / slope;
    if (!(residual_px < 1.0)) return false;
    *focal = 1.0 / slope;
    *centre = -(sr / n - slope * sp / n) / slope;
    return true;
  }
};
}  // namespace

PinholeIntrinsics estimateIntrinsics(const CloudView& cloud)
{
  PinholeIntrinsics k;
  if (cloud.width < 8 || cloud.height < 8) return k;
  LineFit horizontal, vertical;
  const int step = std::max(1, cloud.width / 80);
  for (int v = 0; v < cloud.height; v += step)
    for (int u = 0; u < cloud.width; u += step)
    {
      float x, y, z;
      cloud.point(u, v, x, y, z);
      if (!std::isfinite(x + y + z) || z <= 0.0f) continue;
      horizontal.add(u, x / z);
      vertical.add(v, y / z);
    }
  PinholeIntrinsics fitted;
  if (horizontal.solve(&fitted.fx, &fitted.cx) && vertical.solve(&fitted.fy, &fitted.cy)) k = fitted;
  return k;
}

double estimateFocalLength(const CloudView& cloud)
{
  const PinholeIntrinsics k = estimateIntrinsics(cloud);
  return k.valid() ? k.fx * kReferenceWidth / cloud.width : 0.0;
}

}  // namespace hough_plane_detector
