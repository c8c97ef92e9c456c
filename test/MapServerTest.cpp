#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>
#include <ros/topic.h>

#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

namespace
{
const std::string kManager = "/map_server_manager";
const std::string kNode = "/map_server_detector";

// A map of the office after a few frames, written with the core's own saveMap.
std::vector<DetectedPlane> writeOfficeMap(const std::string& path)
{
  SceneRenderer renderer(makeOfficeRoom());
  PlaneDetector detector{DetectorParams()};
  const auto poses = roomTour(8);
  for (size_t f = 0; f < poses.size(); ++f)
  {
    const RenderedFrame frame = renderer.render(poses[f], KinectNoise(), 500 + f);
    detector.processFrame(frame.view(), frame.camera_to_world, 0.1 * f);
  }
  std::string error;
  EXPECT_TRUE(detector.saveMap(path, &error)) << error;
  return detector.planes();
}

bool loadNodelet()
{
  nodelet::NodeletLoad load;
  load.request.name = kNode;
  load.request.type = "hough_plane_detector/PlaneDetectorNodelet";
  return ros::service::waitForService(kManager + "/load_nodelet", ros::Duration(30.0)) &&
         ros::service::call(kManager + "/load_nodelet", load) && load.response.success;
}
}  // namespace

TEST(MapServer, LoadsItsMapAtStartAndSavesItWhenUnloaded)
{
  const std::string start = "/tmp/hough_plane_detector_map_server_start.map";
  const std::string saved = "/tmp/hough_plane_detector_map_server_saved.map";
  std::remove(saved.c_str());
  const std::vector<DetectedPlane> planes = writeOfficeMap(start);
  ASSERT_GE(planes.size(), 5u);

  ros::NodeHandle nh;
  nh.setParam(kNode + "/map_file", start);
  nh.setParam(kNode + "/save_on_shutdown", saved);
  ASSERT_TRUE(loadNodelet());

  // No cloud ever arrives: the planes come from the file, latched for a subscriber that comes later.
  PlaneArray::ConstPtr received = ros::topic::waitForMessage<PlaneArray>(kNode + "/planes", ros::Duration(20.0));
  ASSERT_TRUE(received);
  ASSERT_EQ(received->planes.size(), planes.size());
  for (size_t i = 0; i < planes.size(); ++i)
  {
    EXPECT_EQ(received->planes[i].id, planes[i].id);
    EXPECT_EQ(received->planes[i].d, planes[i].d);
  }

  nodelet::NodeletUnload unload;
  unload.request.name = kNode;
  ASSERT_TRUE(ros::service::call(kManager + "/unload_nodelet", unload) && unload.response.success);
  PlaneDetector restored{DetectorParams()};
  std::string error;
  ASSERT_TRUE(restored.loadMap(saved, &error)) << error;
  ASSERT_EQ(restored.planes().size(), planes.size());
  for (size_t i = 0; i < planes.size(); ++i)
  {
    EXPECT_EQ(restored.planes()[i].id, planes[i].id);
    EXPECT_EQ(restored.planes()[i].normal, planes[i].normal);
    EXPECT_EQ(restored.planes()[i].d, planes[i].d);
  }
}

// A ~map_file that cannot be read: the node starts with an empty map and says why.
TEST(MapServer, AnUnreadableMapFileLeavesAnEmptyMap)
{
  ros::NodeHandle nh;
  nh.setParam(kNode + "/map_file", std::string("/nonexistent/office.map"));
  nh.setParam(kNode + "/save_on_shutdown", std::string(""));
  ASSERT_TRUE(loadNodelet());
  PlaneArray::ConstPtr received = ros::topic::waitForMessage<PlaneArray>(kNode + "/planes", ros::Duration(3.0));
  EXPECT_FALSE(received) << "nothing to publish before a cloud arrives";
  nodelet::NodeletUnload unload;
  unload.request.name = kNode;
  EXPECT_TRUE(ros::service::call(kManager + "/unload_nodelet", unload) && unload.response.success);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "map_server_test");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
