// Seeds for the fuzzers: a real map (a few frames of the simulated office at resolution 256,
// without its checksum: fuzz_map_file appends one for odd first bytes) and a valid 16 x 16
// cloud in fuzz_cloud_view's input format.
#include <cstdio>
#include <fstream>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

int main(int argc, char** argv)
{
  if (argc != 3) return 2;
  DetectorParams params;
  params.resolution = 256;
  PlaneDetector detector(params);
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(40);
  for (int f = 0; f < 3; ++f)
  {
    const RenderedFrame frame = renderer.render(poses[f], KinectNoise(), f);
    detector.processFrame(frame.view(), frame.camera_to_world, f);
  }
  const std::string bytes = detector.serializeMap();
  std::ofstream out(argv[1], std::ios::binary);
  out.put(1);  // odd: the target recomputes the checksum
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() - sizeof(uint64_t)));

  // width 16, height 16, point_step 12, row_step 192, little-endian, fields x y z (float32).
  std::ofstream cloud(argv[2], std::ios::binary);
  const uint8_t header[] = {16, 16, 12, 192, 0, 0, 3, 0, 0, 7, 1, 4, 7, 2, 8, 7};
  cloud.write(reinterpret_cast<const char*>(header), sizeof(header));
  for (int v = 0; v < 16; ++v)
    for (int u = 0; u < 16; ++u)
    {
      const float p[3] = {0.01f * u, 0.01f * v, 1.0f + 0.002f * u};  // a tilted plane
      cloud.write(reinterpret_cast<const char*>(p), sizeof(p));
    }
  return out && cloud ? 0 : 1;
}
