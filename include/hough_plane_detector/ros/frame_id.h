// Frame ids as tf2 takes them.
#pragma once

#include <string>

namespace hough_plane_detector
{

// tf2 frame ids have no leading '/'; tf1-era recordings (the TUM RGB-D bags) still send them.
inline std::string tf2FrameId(const std::string& frame)
{
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

}  // namespace hough_plane_detector
