// libFuzzer target: arbitrary bytes as a saved map. Half the inputs get a valid checksum
// appended, so the fuzzer reaches the parser behind the checksum test.
#include <cstdint>
#include <memory>
#include <string>

#include "hough_plane_detector/core/plane_detector.h"

using namespace hough_plane_detector;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
  static std::unique_ptr<PlaneDetector> detector = [] {
    DetectorParams params;
    params.resolution = 256;
    return std::unique_ptr<PlaneDetector>(new PlaneDetector(params));
  }();
  if (size == 0) return 0;
  std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1) bytes = PlaneDetector::withMapChecksum(bytes);
  std::string error;
  detector->deserializeMap(bytes, &error);
  return 0;
}
