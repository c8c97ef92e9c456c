// The header of a PCD file, checked before a library parses it (ROS- and PCL-free, fuzzed).
#pragma once

#include <istream>
#include <string>

namespace hough_plane_detector
{

// "" when the stream starts with a complete PCD header (every required key, sizes that agree),
// otherwise what is wrong; reads at most 64 lines.
std::string checkPcdHeader(std::istream& in);

}  // namespace hough_plane_detector
