// The detector as a plain node for rosrun and launch files without a nodelet manager: it loads
// the same nodelet in-process (as pointcloud_to_laserscan's node does), so names, parameters,
// topics and services are the nodelet's.
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv)
{
  ros::init(argc, argv, "hough_plane_detector");
  nodelet::Loader loader(false);  // no manager services: this process runs one nodelet
  const nodelet::M_string remappings(ros::names::getRemappings());
  const nodelet::V_string nodelet_argv;
  if (!loader.load(ros::this_node::getName(), "hough_plane_detector/PlaneDetectorNodelet", remappings, nodelet_argv))
  {
    ROS_FATAL("Could not load hough_plane_detector/PlaneDetectorNodelet (is the package on ROS_PACKAGE_PATH?)");
    return 1;
  }
  ros::spin();
  return 0;
}
