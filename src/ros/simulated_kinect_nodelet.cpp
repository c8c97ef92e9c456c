// A Kinect that needs no hardware: the core's renderer publishes organized depth clouds of a
// simulated room, with the camera's pose on /tf, like openni2_camera plus odometry would.
#include <memory>

#include <geometry_msgs/TransformStamped.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "hough_plane_detector/sim/scene_renderer.h"

namespace hough_plane_detector
{

class SimulatedKinectNodelet : public nodelet::Nodelet
{
public:
  ~SimulatedKinectNodelet() override { timer_.stop(); }

private:
  void onInit() override
  {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& private_nh = getPrivateNodeHandle();
    std::string scene, trajectory;
    double rate;
    int frames_per_lap;
    private_nh.param<std::string>("scene", scene, "office");
    private_nh.param<std::string>("trajectory", trajectory, "room_tour");
    private_nh.param("rate", rate, 10.0);
    private_nh.param("frames_per_lap", frames_per_lap, 120);
    private_nh.param("noise", noise_.coefficient, 1.0);
    private_nh.param("replay_lap", replay_lap_, false);
    private_nh.param<std::string>("world_frame", world_frame_, "odom");
    private_nh.param<std::string>("base_frame", base_frame_, "camera_link");
    private_nh.param<std::string>("optical_frame", optical_frame_, "camera_depth_optical_frame");
    if (scene != "office" && scene != "hall")
    {
      NODELET_ERROR("Unknown ~scene '%s' (office or hall); using office.", scene.c_str());
      scene = "office";
    }
    if (trajectory != "room_tour" && trajectory != "wall_approach")
    {
      NODELET_ERROR("Unknown ~trajectory '%s' (room_tour or wall_approach); using room_tour.", trajectory.c_str());
      trajectory = "room_tour";
    }
    if (!(rate > 0.0 && rate <= 200.0))
    {
      NODELET_ERROR("~rate must be in (0, 200] Hz, got %g; using 10.", rate);
      rate = 10.0;
    }
    frames_per_lap = std::max(2, frames_per_lap);
    renderer_.reset(new SceneRenderer(scene == "hall" ? makeRampStairsHall() : makeOfficeRoom()));
    poses_ = trajectory == "wall_approach" ? wallApproach(frames_per_lap, 3.0, 5.0, 0.9) : roomTour(frames_per_lap);

    // The optical frame's z looks along camera_link's x (REP 103 camera conventions).
    link_to_optical_ = Eigen::Isometry3d::Identity();
    link_to_optical_.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    geometry_msgs::TransformStamped optical = tf2::eigenToTransform(link_to_optical_);
    optical.header.stamp = ros::Time::now();
    optical.header.frame_id = base_frame_;
    optical.child_frame_id = optical_frame_;
    static_broadcaster_.sendTransform(optical);

    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("depth/points", 2);
    timer_ = nh.createTimer(ros::Duration(1.0 / rate), &SimulatedKinectNodelet::publishFrame, this);
    NODELET_INFO("Simulated Kinect: %s scene, %s, %g Hz, noise C = %g, on %s.", scene.c_str(), trajectory.c_str(), rate,
                 noise_.coefficient, cloud_pub_.getTopic().c_str());
  }

  sensor_msgs::PointCloud2::Ptr makeCloud(size_t index) const
  {
    const RenderedFrame frame = renderer_->render(poses_[index], noise_, static_cast<uint32_t>(index));
    sensor_msgs::PointCloud2::Ptr cloud(new sensor_msgs::PointCloud2);
    cloud->header.frame_id = optical_frame_;
    sensor_msgs::PointCloud2Modifier modifier(*cloud);
    modifier.setPointCloud2FieldsByString(1, "xyz");
    modifier.resize(static_cast<size_t>(frame.width) * frame.height);
    cloud->width = frame.width;
    cloud->height = frame.height;
    cloud->row_step = cloud->point_step * cloud->width;
    cloud->is_dense = false;
    sensor_msgs::PointCloud2Iterator<float> it(*cloud, "x");
    for (size_t i = 0; i < static_cast<size_t>(frame.width) * frame.height; ++i, ++it)
    {
      it[0] = frame.xyz[3 * i];
      it[1] = frame.xyz[3 * i + 1];
      it[2] = frame.xyz[3 * i + 2];
    }
    return cloud;
  }

  void publishFrame(const ros::TimerEvent&)
  {
    const size_t index = frame_ % poses_.size();
    ++frame_;
    sensor_msgs::PointCloud2::Ptr cloud;
    if (!replay_lap_)
    {
      cloud = makeCloud(index);
    }
    else
    {
      // Rendering takes tens of ms: long runs at high rates replay the first lap's clouds.
      if (lap_.size() <= index) lap_.push_back(makeCloud(index));
      cloud.reset(new sensor_msgs::PointCloud2(*lap_[index]));
    }
    const ros::Time stamp = ros::Time::now();
    geometry_msgs::TransformStamped odom = tf2::eigenToTransform(poses_[index] * link_to_optical_.inverse());
    odom.header.stamp = stamp;
    odom.header.frame_id = world_frame_;
    odom.child_frame_id = base_frame_;
    broadcaster_.sendTransform(odom);
    cloud->header.stamp = stamp;
    cloud_pub_.publish(cloud);  // published as a shared pointer: zero copy to nodelets
  }

  std::unique_ptr<SceneRenderer> renderer_;
  std::vector<Eigen::Isometry3d> poses_;
  KinectNoise noise_;
  Eigen::Isometry3d link_to_optical_;
  std::string world_frame_, base_frame_, optical_frame_;
  size_t frame_ = 0;
  bool replay_lap_ = false;
  std::vector<sensor_msgs::PointCloud2::ConstPtr> lap_;
  ros::Publisher cloud_pub_;
  ros::Timer timer_;
  tf2_ros::TransformBroadcaster broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
};

}  // namespace hough_plane_detector

PLUGINLIB_EXPORT_CLASS(hough_plane_detector::SimulatedKinectNodelet, nodelet::Nodelet)
