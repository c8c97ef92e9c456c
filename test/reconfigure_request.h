// dynamic_reconfigure requests for the ROS tests: one parameter per request, called and checked.
#pragma once

#include <string>

#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

namespace hough_plane_detector
{

inline dynamic_reconfigure::Reconfigure setInt(const std::string& name, int value)
{
  dynamic_reconfigure::Reconfigure srv;
  dynamic_reconfigure::IntParameter parameter;
  parameter.name = name;
  parameter.value = value;
  srv.request.config.ints.push_back(parameter);
  return srv;
}

inline dynamic_reconfigure::Reconfigure setDouble(const std::string& name, double value)
{
  dynamic_reconfigure::Reconfigure srv;
  dynamic_reconfigure::DoubleParameter parameter;
  parameter.name = name;
  parameter.value = value;
  srv.request.config.doubles.push_back(parameter);
  return srv;
}

template <class Srv>
Srv call(const std::string& name, Srv srv)
{
  EXPECT_TRUE(ros::service::waitForService(name, ros::Duration(30.0))) << name;
  EXPECT_TRUE(ros::service::call(name, srv)) << name;
  return srv;
}

}  // namespace hough_plane_detector
