// The detector as a plain node for rosrun and launch files without a nodelet manager: the
// same PlaneDetectorRos as the nodelet, so names, parameters, topics and services match.
#include <ros/ros.h>

#include "hough_plane_detector/ros/plane_detector_ros.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "hough_plane_detector");
  hough_plane_detector::PlaneDetectorRos detector(ros::NodeHandle(), ros::NodeHandle("~"), ros::this_node::getName());
  ros::spin();
  return 0;
}
