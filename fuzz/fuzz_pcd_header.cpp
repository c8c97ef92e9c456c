// libFuzzer target: arbitrary bytes as the start of a PCD file, through the header check that
// stands before PCL's reader (which crashed on one line of text).
#include <cstdint>
#include <sstream>
#include <string>

#include "hough_plane_detector/tools/pcd_header.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  hough_plane_detector::checkPcdHeader(in);
  return 0;
}
