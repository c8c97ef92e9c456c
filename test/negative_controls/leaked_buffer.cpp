// make soak-control links this into the nodelet library: loading the library loses a buffer,
// so the soak's leak check (scripts/soak_nodelet.sh with LEAK_EXPECTED=1) must find a leak
// whose stack passes through this package. Never part of a product build.
#include <cstddef>

namespace hough_plane_detector
{
namespace negative_control
{

char* volatile kept = nullptr;  // volatile: the allocation cannot be optimised away

__attribute__((noinline)) void loseABuffer()
{
  kept = new char[4096];
  kept[0] = 1;
  kept = nullptr;  // the only pointer to it is gone: definitely lost
}

const bool lost = (loseABuffer(), true);

}  // namespace negative_control
}  // namespace hough_plane_detector
