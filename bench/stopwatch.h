// The benchmarks' one millisecond timer.
#pragma once

#include <chrono>

namespace hough_plane_detector
{

using Clock = std::chrono::steady_clock;

// Milliseconds since `start`.
inline double msSince(Clock::time_point start)
{
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace hough_plane_detector
