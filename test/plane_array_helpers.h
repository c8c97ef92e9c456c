// Helpers of the rostests that read the detector's ~planes: a recorder and a match count.
#pragma once

#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <ros/ros.h>

#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/sim/scene_renderer.h"

namespace hough_plane_detector
{
namespace test
{

// Keeps every PlaneArray published on `topic` from its construction on.
class PlaneArrayRecorder
{
public:
  explicit PlaneArrayRecorder(const std::string& topic = "/hough_plane_detector/planes")
  {
    subscriber_ = nh_.subscribe<PlaneArray>(topic, 100, [this](const PlaneArray::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      received_.push_back(m);
    });
  }
  // Whether the detector's publisher is connected to this subscription.
  bool connected() const { return subscriber_.getNumPublishers() > 0; }
  // Whether an array stamped `stamp` (within 1 us) has arrived.
  bool receivedStamp(double stamp) const
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const PlaneArray::ConstPtr& m : received_)
      if (std::abs(m->header.stamp.toSec() - stamp) < 1e-6) return true;
    return false;
  }
  std::vector<PlaneArray::ConstPtr> received() const
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return received_;
  }

private:
  ros::NodeHandle nh_;
  ros::Subscriber subscriber_;
  mutable std::mutex mutex_;
  std::vector<PlaneArray::ConstPtr> received_;
};

// How many planes of the array are `truth` within angle_tolerance (rad) and distance_tolerance (m), either sign.
inline int matchesOf(const PlaneArray& planes, const TruePlane& truth, double angle_tolerance, double distance_tolerance)
{
  int matches = 0;
  for (const Plane& p : planes.planes)
  {
    const Eigen::Vector3d n(p.normal.x, p.normal.y, p.normal.z);
    const double sign = n.dot(truth.normal) >= 0.0 ? 1.0 : -1.0;
    matches += std::acos(std::min(1.0, std::abs(n.dot(truth.normal)))) < angle_tolerance &&
               std::abs(sign * p.d - truth.d) < distance_tolerance;
  }
  return matches;
}

}  // namespace test
}  // namespace hough_plane_detector
