// Long-run check of the core: thousands of simulated frames through one detector, printing
// resident memory, Hough chunks, planes and ms per frame as it goes. Not a test: figures.
// Usage: soak_detector [FRAMES]   (default 10000; 120 rendered frames are cycled)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "hough_plane_detector/tools/cli_options.h"

using namespace hough_plane_detector;

namespace
{
long residentKilobytes()
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6);
  return -1;
}
}  // namespace

int main(int argc, char** argv)
{
  int frames = 10000;
  if (argc > 1 && (!parseInteger(argv[1], &frames) || frames < 1))
  {
    std::fprintf(stderr, "usage: soak_detector [FRAMES > 0], got '%s'\n", argv[1]);
    return 2;
  }
  const int lap = 120;
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(lap);
  std::vector<RenderedFrame> rendered;
  for (int f = 0; f < lap; ++f) rendered.push_back(renderer.render(poses[f], KinectNoise(), 900 + f));
  PlaneDetector detector{DetectorParams()};
  std::printf("soak: %d frames of the simulated office (%d rendered frames cycled), default parameters\n", frames, lap);
  const long rss_frames = residentKilobytes();
  std::printf("resident memory with the rendered frames loaded, before the detector runs: %.1f MB\n", rss_frames / 1024.0);
  std::printf("  frame   RSS MB   Hough MB   chunks   planes   median ms (last 500)\n");
  std::vector<double> ms;
  long rss_after_warmup = 0, rss_max_after_warmup = 0;
  for (int f = 0; f < frames; ++f)
  {
    const RenderedFrame& frame = rendered[f % lap];
    std::string error;
    if (!detector.processFrame(frame.view(), frame.camera_to_world, 0.1 * f, &error))
    {
      std::fprintf(stderr, "frame %d: %s\n", f, error.c_str());
      return 1;
    }
    ms.push_back(detector.lastTimings().total_ms);
    if ((f + 1) % 500 == 0 || f + 1 == frames)
    {
      std::vector<double> last(ms.end() - std::min<size_t>(ms.size(), 500), ms.end());
      std::sort(last.begin(), last.end());
      const long rss = residentKilobytes();
      if (f + 1 == 1000) rss_after_warmup = rss;
      if (f + 1 > 1000) rss_max_after_warmup = std::max(rss_max_after_warmup, rss);
      std::printf("  %6d   %6.1f   %8.2f   %6zu   %6zu   %6.2f\n", f + 1, rss / 1024.0,
                  detector.memory().global_bytes / 1e6, detector.memory().global_chunks, detector.planes().size(),
                  last[last.size() / 2]);
    }
  }
  if (rss_after_warmup > 0 && rss_max_after_warmup > 0)
    std::printf("resident memory after frame 1000: %.1f MB; highest later: %.1f MB (growth %+.1f MB)\n",
                rss_after_warmup / 1024.0, rss_max_after_warmup / 1024.0,
                (rss_max_after_warmup - rss_after_warmup) / 1024.0);
  return 0;
}
