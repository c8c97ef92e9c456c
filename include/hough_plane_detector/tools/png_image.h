// Writes 8-bit RGB images as PNG (libpng), for the demo's picture of the segmentation.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hough_plane_detector
{

// rgb holds width * height * 3 bytes, row by row; false with `error` set on failure.
bool writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb, std::string* error);

}  // namespace hough_plane_detector
