// Waiting in rostests on a condition rather than for a fixed time.
#pragma once

#include <ros/ros.h>

namespace hough_plane_detector
{
namespace test
{
// Polls `done` every 50 ms until it holds or `seconds` (wall time) pass; whether it held. Tests
// wait on what they need rather than for a fixed time, which a loaded machine can outlast.
template <class Done>
bool waitUntil(Done done, double seconds)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (!done())
  {
    if (ros::WallTime::now() > end) return false;
    ros::WallDuration(0.05).sleep();
  }
  return true;
}
}  // namespace test
}  // namespace hough_plane_detector
