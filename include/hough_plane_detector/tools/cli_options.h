// Detector parameters as command-line flags (the names dynamic_reconfigure uses) and the
// one-JSON-object-per-frame output of the offline tools.
#pragma once

#include <string>
#include <vector>

#include "hough_plane_detector/core/plane_detector.h"

namespace hough_plane_detector
{

// The whole text as an integer / a finite number; false (out untouched) for anything else ("12abc", "", "nan").
bool parseInteger(const std::string& text, int* out);
bool parseFinite(const std::string& text, double* out);

// Sets the parameter `name` from text; false with `error` set for an unknown name or bad value.
bool setDetectorParam(DetectorParams& params, const std::string& name, const std::string& value, std::string* error);
// "name (type, default)" lines for --help.
std::vector<std::string> detectorParamHelp();

// {"frame": 0, "stamp": 12.34, "frame_id": "odom", "ms": 4.2, "planes": [...]}; `outlines`,
// when given, holds each plane's region shapes (PlaneDetector::outlines), in the planes' order.
std::string frameToJson(int frame, double stamp, const std::string& frame_id, double ms,
                        const std::vector<DetectedPlane>& planes,
                        const std::vector<std::vector<PlaneOutline>>& outlines = {});

}  // namespace hough_plane_detector
