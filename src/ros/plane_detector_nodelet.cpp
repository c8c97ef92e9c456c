// The detector as a nodelet: PlaneDetectorRos in a nodelet manager, zero-copy clouds from the
// camera's nodelets in the same manager.
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "hough_plane_detector/ros/plane_detector_ros.h"

namespace hough_plane_detector
{

class PlaneDetectorNodelet : public nodelet::Nodelet
{
private:
  void onInit() override { detector_.reset(new PlaneDetectorRos(getNodeHandle(), getPrivateNodeHandle(), getName())); }

  std::unique_ptr<PlaneDetectorRos> detector_;
};

}  // namespace hough_plane_detector

PLUGINLIB_EXPORT_CLASS(hough_plane_detector::PlaneDetectorNodelet, nodelet::Nodelet)
