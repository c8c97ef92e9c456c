// Depth noise of the supported sensors, as published, and the focal length read from an
// organized cloud itself: every noise test of the detector asks this model, not a constant.
#pragma once

#include <string>
#include <vector>

#include "hough_plane_detector/core/cloud_view.h"

namespace hough_plane_detector
{

// The `sensor_model` parameter (an int so that dynamic_reconfigure shows it as an enum).
enum SensorModel : int
{
  kKinectV1 = 0,       // structured light, eq. 11 of the paper + 1/8 px disparity steps, b = 7.5 cm
  kXtion = 1,          // the same PrimeSense principle (eq. 11), b = 7.5 cm
  kRealsenseD400 = 2,  // active stereo: sigma = z^2 * 0.08 px / (f * 5 cm) (Intel's RMS subpixel error)
  kTof = 3,            // time of flight (Kinect v2): sigma = 1.5 - 0.5 z + 0.3 z^2 mm (Fankhauser et al. 2015)
};
constexpr int kSensorModelCount = 4;

// "kinect_v1", "xtion", "realsense_d400", "tof"; "unknown" out of range.
const char* sensorModelName(int model);
// Reads a name or its number; false (model untouched) for anything else.
bool parseSensorModel(const std::string& text, int* model);

class DepthNoiseModel
{
public:
  // coefficient: C of eq. 11 for the structured-light sensors, a scale on the published curve
  // for the others; 0 turns the noise model off (sigma 0, no quantization). focal_px <= 0
  // takes the sensor's nominal VGA focal length.
  explicit DepthNoiseModel(int model = kKinectV1, double coefficient = 1.0, double focal_px = 0.0);

  // Standard deviation of a depth measurement at depth z (m), quantization included; from a
  // table of 1 cm steps up to 12 m (linear between them: the curves are smooth), computed above.
  double sigma(double depth) const
  {
    const double at = depth * kTableStepsPerMetre;
    if (!(at >= 0.0) || at >= kTableSize - 1) return computeSigma(depth);
    const int i = static_cast<int>(at);
    const double w = at - i;
    return (1.0 - w) * sigma_table_[i] + w * sigma_table_[i + 1];
  }
  // The same without the table.
  double computeSigma(double depth) const;
  // Depth step of the sensor's disparity quantization at depth z (0 where it has none).
  double quantizationStep(double depth) const;
  bool enabled() const { return coefficient_ > 0.0; }
  double focal() const { return focal_px_; }
  int model() const { return model_; }

private:
  static constexpr int kTableStepsPerMetre = 100;
  static constexpr int kTableSize = 12 * kTableStepsPerMetre + 1;
  int model_;
  double coefficient_;
  double focal_px_;
  std::vector<double> sigma_table_;
};

// Eq. 11 of the paper: a Kinect's random depth noise (m) at depth z for noise coefficient C.
double structuredLightSigma(double depth, double coefficient);

// Nominal focal length in pixels of the sensor's 640-pixel-wide depth image.
double nominalFocalLength(int model);

// Pinhole projection of an organized cloud at its own resolution: u = fx x / z + cx.
struct PinholeIntrinsics
{
  double fx = 0, fy = 0, cx = 0, cy = 0;
  bool valid() const { return fx > 0.0 && fy > 0.0; }
};

// fx, cx from x/z against u and fy, cy from y/z against v (least-squares lines over a grid of
// pixels); invalid when the cloud has too few valid points or is no pinhole projection (a fit
// residual above a pixel).
PinholeIntrinsics estimateIntrinsics(const CloudView& cloud);

// The horizontal focal length of an organized cloud from its own points (x/z = (u - cx) / fx,
// a least-squares line over a grid of pixels), for a 640-pixel-wide image (f * 640 / width:
// the sensors measure disparity at that width whatever the cloud's); 0 when the cloud has too
// few valid points or is not a pinhole projection (a fit residual above a pixel).
double estimateFocalLength(const CloudView& cloud);

}  // namespace hough_plane_detector
