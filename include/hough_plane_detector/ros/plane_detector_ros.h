// The ROS face of the detector: organized clouds in (tf2 to the world frame), the persistent
// plane map out (planes, markers, pcl_msgs outputs, segmented cloud), services to reset, save
// and load the map, dynamic_reconfigure and diagnostics. The nodelet and the plain node each
// hold one. One mutex guards the map on every path.
#pragma once

#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <message_filters/subscriber.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include "hough_plane_detector/HoughPlaneDetectorConfig.h"
#include "hough_plane_detector/LoadMap.h"
#include "hough_plane_detector/SaveMap.h"
#include "hough_plane_detector/core/plane_detector.h"

namespace hough_plane_detector
{

class PlaneDetectorRos
{
public:
  // Reads its parameters from private_nh, advertises there, subscribes to nh's cloud_in;
  // `name` prefixes its log lines and names its diagnostics.
  PlaneDetectorRos(ros::NodeHandle nh, ros::NodeHandle private_nh, const std::string& name);
  // Stops what calls back into it first, then saves the map to ~save_on_shutdown if set.
  ~PlaneDetectorRos();
  PlaneDetectorRos(const PlaneDetectorRos&) = delete;
  PlaneDetectorRos& operator=(const PlaneDetectorRos&) = delete;

private:
  void readParameters(ros::NodeHandle& private_nh);
  void loadStartupMap(ros::NodeHandle& private_nh);
  void advertise(ros::NodeHandle& private_nh);
  void subscribe(ros::NodeHandle& nh, int queue_size, double tf_tolerance, int concurrency_level);

  bool frameUnknown(const std::string& frame) const;
  void checkFrameKnown(const sensor_msgs::PointCloud2ConstPtr& cloud);
  bool timeJumpedBack(const ros::Time& stamp);
  void failureCallback(const sensor_msgs::PointCloud2ConstPtr& cloud,
                       tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void cloudCallback(const sensor_msgs::PointCloud2ConstPtr& cloud);
  // Caller holds map_mutex_.
  void publishMap();
  void publishLabels(const sensor_msgs::PointCloud2& cloud, const CloudView& view);
  void reconfigure(HoughPlaneDetectorConfig& config, uint32_t level);
  bool resetService(std_srvs::Empty::Request&, std_srvs::Empty::Response&);
  bool saveMapService(SaveMap::Request& req, SaveMap::Response& res);
  bool loadMapService(LoadMap::Request& req, LoadMap::Response& res);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  // map_mutex_, held until the returned lock goes (src/ros/map_lock.cpp; make tsan-control
  // links a version that does not lock, to prove the race check can fail).
  std::unique_lock<std::mutex> lockMap();

  std::string name_;
  std::mutex map_mutex_;  // guards detector_, params_ and the counters on every path
  std::unique_ptr<PlaneDetector> detector_;
  DetectorParams params_;
  std::string world_frame_;
  bool latch_ = true;
  std::string save_on_shutdown_;  // path the map is saved to when this object goes
  ros::Time last_stamp_;
  double last_ms_ = 0.0;
  int frames_processed_ = 0, frames_dropped_ = 0, frames_rejected_ = 0;
  uint64_t frames_queue_dropped_ = 0;
  uint32_t last_seq_ = 0;
  static constexpr double kTimeJumpTolerance = 1.0;  // s; clouds a little out of order are no jump
  ros::Time last_arrival_stamp_;
  int time_jumps_back_ = 0;
  std::deque<ros::WallTime> arrivals_;

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::mutex tf_reset_mutex_;  // one tf reset at a time; never taken with map_mutex_ held
  ros::CallbackQueue cloud_queue_;  // declared before the filter and subscriber: outlives them
  std::unique_ptr<ros::AsyncSpinner> cloud_spinner_;
  std::unique_ptr<message_filters::Subscriber<sensor_msgs::PointCloud2>> subscriber_;
  std::unique_ptr<tf2_ros::MessageFilter<sensor_msgs::PointCloud2>> tf_filter_;
  ros::Publisher planes_pub_, markers_pub_, segmented_pub_, coefficients_pub_, inliers_pub_;
  ros::ServiceServer reset_srv_, save_srv_, load_srv_;
  boost::recursive_mutex config_mutex_;  // dynamic_reconfigure's own; the map has map_mutex_
  std::unique_ptr<dynamic_reconfigure::Server<HoughPlaneDetectorConfig>> reconfigure_server_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  ros::Timer diagnostics_timer_;
};

}  // namespace hough_plane_detector
