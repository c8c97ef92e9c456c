// Detector parameters as command-line flags (the names dynamic_reconfigure uses) and the
// one-JSON-object-per-frame output of the offline tools.
#pragma once

#include <string>
#include <vector>

#include <boost/program_options.hpp>

#include "hough_plane_detector/core/plane_detector.h"

namespace hough_plane_detector
{

// The whole text as an integer / a finite number; false (out untouched) for anything else ("12abc", "", "nan").
bool parseInteger(const std::string& text, int* out);
bool parseFinite(const std::string& text, double* out);

// Sets the parameter `name` from text; false with `error` set for an unknown name or bad value.
bool setDetectorParam(DetectorParams& params, const std::string& name, const std::string& value, std::string* error);
// Adds --NAME VALUE for every detector parameter to `visible` (the names dynamic_reconfigure
// uses) and, spelt with dashes, to `hidden`; each value is set in `params` through
// setDetectorParam when the options are notified, a bad one throwing
// boost::program_options::error with setDetectorParam's message. `params` must outlive the parse.
void addDetectorParamOptions(DetectorParams& params, boost::program_options::options_description& visible,
                             boost::program_options::options_description& hidden);
// boost::program_options' parse, store and notify of argv: false with `error` set (the
// library's message, or a parameter's) on anything it refuses.
bool parseCommandLine(int argc, char** argv, const boost::program_options::options_description& options,
                      const boost::program_options::positional_options_description& positional,
                      boost::program_options::variables_map& values, std::string* error);
// A cloud given in its camera's own frame (a PCD file, an osd-learn frame) says nothing of
// gravity: world_z_up becomes 0 unless the command line set it, either spelling.
void assumeCameraFrame(const boost::program_options::variables_map& values, DetectorParams& params);

// {"frame": 0, "stamp": 12.34, "frame_id": "odom", "ms": 4.2, "planes": [...]}; `outlines`,
// when given, holds each plane's region shapes (PlaneDetector::outlines), in the planes' order.
std::string frameToJson(int frame, double stamp, const std::string& frame_id, double ms,
                        const std::vector<DetectedPlane>& planes,
                        const std::vector<std::vector<PlaneOutline>>& outlines = {});

}  // namespace hough_plane_detector
