// Concurrent clouds, reconfigure requests and service calls into one running detector nodelet:
// every call is answered, the map stays consistent, and the node keeps detecting afterwards.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

#include <ros/ros.h>
#include <std_srvs/Empty.h>

#include "hough_plane_detector/LoadMap.h"
#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/SaveMap.h"
#include "reconfigure_request.h"

using namespace hough_plane_detector;

namespace
{
const std::string kNode = "/hough_plane_detector";

std::mutex mutex;
PlaneArray::ConstPtr last_planes;
int arrays_received = 0;

void onPlanes(const PlaneArray::ConstPtr& m)
{
  std::lock_guard<std::mutex> lock(mutex);
  last_planes = m;
  ++arrays_received;
}

bool hasFloor(const PlaneArray& array)
{
  for (const Plane& p : array.planes)
    if (std::abs(std::abs(p.normal.z) - 1.0) < 0.01 && std::abs(p.d) < 0.02) return true;
  return false;
}
}  // namespace

TEST(Concurrency, CloudsReconfigureAndServicesTogether)
{
  ros::NodeHandle private_nh("~");
  const double stress_seconds = private_nh.param("stress_seconds", 15.0);
  // With one cloud thread no two frames meet in the map: half of what this test is for.
  int concurrency_level = 0;
  ASSERT_TRUE(ros::param::get(kNode + "/concurrency_level", concurrency_level));
  ASSERT_GT(concurrency_level, 1) << "the detector would process one cloud at a time";
  ASSERT_TRUE(ros::service::waitForService(kNode + "/reset", ros::Duration(60.0)));
  ASSERT_TRUE(ros::service::waitForService(kNode + "/set_parameters", ros::Duration(60.0)));
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(stress_seconds);
  std::atomic<int> failed_calls{0}, reconfigures{0}, service_rounds{0}, save_failures{0};

  std::thread reconfigurer([&] {
    for (int i = 0; ros::WallTime::now() < end; ++i)
    {
      auto srv = i % 20 == 19 ? setInt("resolution", (i / 20) % 2 ? 1024 : 512)  // a new grid now and then
                              : setDouble("thinning_rate", i % 2 ? 0.04 : 0.06);
      if (!ros::service::call(kNode + "/set_parameters", srv)) ++failed_calls;
      ++reconfigures;
      ros::WallDuration(0.05).sleep();
    }
  });
  std::thread services([&] {
    const std::string path = "/tmp/hough_plane_detector_concurrency_" + std::to_string(getpid()) + ".map";
    while (ros::WallTime::now() < end)
    {
      SaveMap save;
      save.request.path = path;
      if (!ros::service::call(kNode + "/save_map", save)) ++failed_calls;
      if (!save.response.success) ++save_failures;
      LoadMap load;
      load.request.path = path;  // may be refused when the grid changed in between: that is an answer
      if (!ros::service::call(kNode + "/load_map", load)) ++failed_calls;
      std_srvs::Empty reset;
      if (service_rounds % 5 == 4 && !ros::service::call(kNode + "/reset", reset)) ++failed_calls;
      ++service_rounds;
      ros::WallDuration(0.1).sleep();
    }
    std::remove(path.c_str());
  });
  reconfigurer.join();
  services.join();
  EXPECT_EQ(failed_calls.load(), 0) << "service calls that got no answer";
  EXPECT_EQ(save_failures.load(), 0);
  EXPECT_GT(reconfigures.load(), 10);
  EXPECT_GT(service_rounds.load(), 10);
  std::printf("%d reconfigure requests and %d save/load rounds during %.0f s of 10 Hz clouds\n", reconfigures.load(),
              service_rounds.load(), stress_seconds);

  // Back to the defaults; the node goes on and finds the floor again.
  call(kNode + "/set_parameters", setInt("resolution", 1024));
  call(kNode + "/set_parameters", setDouble("thinning_rate", 0.05));
  const int received = [] {
    std::lock_guard<std::mutex> lock(mutex);
    return arrays_received;
  }();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(60.0);
  bool floor = false;
  while (!floor && ros::WallTime::now() < deadline)
  {
    ros::WallDuration(0.2).sleep();
    std::lock_guard<std::mutex> lock(mutex);
    floor = arrays_received > received && last_planes && hasFloor(*last_planes);
  }
  EXPECT_TRUE(floor) << "no floor in the map after the stress";
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_concurrency");
  ros::NodeHandle nh;
  ros::Subscriber planes = nh.subscribe(kNode + "/planes", 10, onPlanes);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
