#include "hough_plane_detector/tools/png_image.h"

#include <cstdio>

#include <png.h>

namespace hough_plane_detector
{

bool writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb, std::string* error)
{
  if (rgb.size() != static_cast<size_t>(width) * height * 3)
  {
    if (error) *error = "image buffer does not match its size";
    return false;
  }
  FILE* file = std::fopen(path.c_str(), "wb");
  if (!file)
  {
    if (error) *error = "cannot write " + path;
    return false;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png)))
  {
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    if (error) *error = "libpng failed writing " + path;
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y)
    png_write_row(png, const_cast<png_bytep>(rgb.data() + static_cast<size_t>(y) * width * 3));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(file);
  return true;
}

}  // namespace hough_plane_detector
