// PlaneDetectorRos: the detector's ROS layer (plane_detector_ros.h).
#include "hough_plane_detector/ros/plane_detector_ros.h"

#include <cmath>

#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/ros/frame_id.h"
#include "hough_plane_detector/ros/plane_markers.h"
#include "hough_plane_detector/ros/point_cloud2_layout.h"

namespace hough_plane_detector
{

namespace
{
constexpr int kMapUpdateQueue = 10;  // outgoing ~planes and ~coefficients messages per subscriber

// The .cfg declares the same names as the core's parameter list: one copy serves both ways.
template <class To, class From>
To copyParams(const From& from)
{
  To to;
#define HPD_COPY(type, name) to.name = from.name;
  HOUGH_PLANE_DETECTOR_PARAMS(HPD_COPY)
#undef HPD_COPY
  return to;
}

HoughPlaneDetectorConfig toConfig(const DetectorParams& from) { return copyParams<HoughPlaneDetectorConfig>(from); }
DetectorParams toParams(const HoughPlaneDetectorConfig& from) { return copyParams<DetectorParams>(from); }
}  // namespace

PlaneDetectorRos::~PlaneDetectorRos()
{
  // Stop what calls back into this object before its members go (DEBIAN-ROS pitfall 12);
  // stop() joins the cloud threads, so no frame is being processed past this line.
  diagnostics_timer_.stop();
  if (cloud_spinner_) cloud_spinner_->stop();
  tf_filter_.reset();
  subscriber_.reset();
  if (!save_on_shutdown_.empty() && detector_)
  {
    const auto lock = lockMap();
    std::string error;
    if (detector_->saveMap(save_on_shutdown_, &error))
      ROS_INFO_NAMED(name_, "Saved %zu planes to ~save_on_shutdown %s.", detector_->planes().size(), save_on_shutdown_.c_str());
    else
      ROS_ERROR_NAMED(name_, "~save_on_shutdown %s: %s", save_on_shutdown_.c_str(), error.c_str());
  }
}

PlaneDetectorRos::PlaneDetectorRos(ros::NodeHandle nh, ros::NodeHandle private_nh, const std::string& name)
  : name_(name)
{
  private_nh.param<std::string>("world_frame", world_frame_, "odom");
  world_frame_ = tf2FrameId(world_frame_);
  private_nh.param("latch", latch_, true);  // a map server: late subscribers get the map
  int queue_size;
  private_nh.param("queue_size", queue_size, 2);
  // tf2's filter waits for tf data this much newer than a cloud; a clouds' queue must hold
  // rate x tolerance clouds or every cloud is dropped (0.1 s with a queue of 2 lost all 30 Hz
  // clouds), so by default a transform at the cloud's stamp is enough.
  double tf_tolerance;
  private_nh.param("transform_tolerance", tf_tolerance, 0.0);
  int concurrency_level;
  private_nh.param("concurrency_level", concurrency_level, 1);
  readParameters(private_nh);
  detector_.reset(new PlaneDetector(params_));
  loadStartupMap(private_nh);
  tf_buffer_.reset(new tf2_ros::Buffer);
  tf_listener_.reset(new tf2_ros::TransformListener(*tf_buffer_));
  advertise(private_nh);
  if (!detector_->planes().empty()) publishMap();  // the ~map_file's planes, latched

  reconfigure_server_.reset(new dynamic_reconfigure::Server<HoughPlaneDetectorConfig>(config_mutex_, private_nh));
  {
    boost::recursive_mutex::scoped_lock lock(config_mutex_);
    reconfigure_server_->updateConfig(toConfig(params_));
  }
  reconfigure_server_->setCallback(
      boost::bind(&PlaneDetectorRos::reconfigure, this, boost::placeholders::_1, boost::placeholders::_2));

  diagnostics_.reset(new diagnostic_updater::Updater(nh, private_nh, name_));
  diagnostics_->setHardwareID("none");
  diagnostics_->add("plane map", this, &PlaneDetectorRos::diagnose);
  diagnostics_timer_ = private_nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { diagnostics_->update(); });
  subscribe(nh, queue_size, tf_tolerance, concurrency_level);
  ROS_INFO_NAMED(name_, "Detecting planes in %s (world frame %s), resolution %d, %d cloud(s) at once.",
                 subscriber_->getTopic().c_str(), world_frame_.c_str(), params_.resolution, std::max(1, concurrency_level));
}

void PlaneDetectorRos::readParameters(ros::NodeHandle& private_nh)
{
  // Every detector parameter from the private handle by its core name, defaults from the core.
  DetectorParams defaults;
#define HPD_READ(type, name) private_nh.param(#name, params_.name, defaults.name);
  HOUGH_PLANE_DETECTOR_PARAMS(HPD_READ)
#undef HPD_READ
  std::string problem;
  if (!params_.validate(&problem))
  {
    ROS_ERROR_NAMED(name_, "Invalid detector parameters (%s); using the defaults.", problem.c_str());
    params_ = DetectorParams();
  }
}

void PlaneDetectorRos::loadStartupMap(ros::NodeHandle& private_nh)
{
  // A map server: the map of the last run, and where this run's map goes at shutdown.
  std::string map_file;
  private_nh.param<std::string>("map_file", map_file, "");
  private_nh.param<std::string>("save_on_shutdown", save_on_shutdown_, "");
  if (map_file.empty()) return;
  std::string error;
  if (detector_->loadMap(map_file, &error))
    ROS_INFO_NAMED(name_, "Loaded %zu planes from ~map_file %s.", detector_->planes().size(), map_file.c_str());
  else
    ROS_ERROR_NAMED(name_, "~map_file %s not loaded (%s); starting with an empty map.", map_file.c_str(), error.c_str());
}

void PlaneDetectorRos::advertise(ros::NodeHandle& private_nh)
{
  // The map's topics are small and every update counts: a queue of 10 holds a second of frames
  // while roscpp's writer thread waits for a core (with 2, a clean-clone test run once received
  // 10 of a played bag's 12 updates, no cloud skipped). The frame-sized topics keep the newest.
  planes_pub_ = private_nh.advertise<PlaneArray>("planes", kMapUpdateQueue, latch_);
  markers_pub_ = private_nh.advertise<visualization_msgs::MarkerArray>("markers", 2, latch_);
  segmented_pub_ = private_nh.advertise<sensor_msgs::PointCloud2>("segmented_cloud", 2);
  coefficients_pub_ = private_nh.advertise<ModelCoefficientsArray>("coefficients", kMapUpdateQueue, latch_);
  inliers_pub_ = private_nh.advertise<ClusterPointIndices>("inliers", 2);
  reset_srv_ = private_nh.advertiseService("reset", &PlaneDetectorRos::resetService, this);
  save_srv_ = private_nh.advertiseService("save_map", &PlaneDetectorRos::saveMapService, this);
  load_srv_ = private_nh.advertiseService("load_map", &PlaneDetectorRos::loadMapService, this);
}

void PlaneDetectorRos::subscribe(ros::NodeHandle& nh, int queue_size, double tf_tolerance, int concurrency_level)
{
  // Clouds get their own queue and threads: services answer while a frame is processed, and
  // tf2's filter keeps a raw pointer to its queue, which must outlive the filter. The manager's
  // queues do not (at unload the filter's destructor raced the queue's, seen by ThreadSanitizer).
  ros::NodeHandle cloud_nh(nh);
  cloud_nh.setCallbackQueue(&cloud_queue_);
  subscriber_.reset(new message_filters::Subscriber<sensor_msgs::PointCloud2>(cloud_nh, "cloud_in", queue_size));
  tf_filter_.reset(new tf2_ros::MessageFilter<sensor_msgs::PointCloud2>(*subscriber_, *tf_buffer_, world_frame_,
                                                                        queue_size, cloud_nh));
  tf_filter_->setTolerance(ros::Duration(tf_tolerance));
  tf_filter_->registerCallback(boost::bind(&PlaneDetectorRos::cloudCallback, this, boost::placeholders::_1));
  tf_filter_->registerFailureCallback(
      boost::bind(&PlaneDetectorRos::failureCallback, this, boost::placeholders::_1, boost::placeholders::_2));
  // tf2's filter holds a cloud of a frame tf has never heard of until newer such clouds push it
  // out of the queue; say so at arrival instead.
  subscriber_->registerCallback(boost::bind(&PlaneDetectorRos::checkFrameKnown, this, boost::placeholders::_1));
  cloud_spinner_.reset(new ros::AsyncSpinner(std::max(1, concurrency_level), &cloud_queue_));
  cloud_spinner_->start();
}

bool PlaneDetectorRos::frameUnknown(const std::string& frame) const
{
  // No transform to the world at any time: tf has never heard of the frame (or of a link to it).
  return !frame.empty() && tf2FrameId(frame) != world_frame_ &&
         !tf_buffer_->canTransform(world_frame_, tf2FrameId(frame), ros::Time(0));
}

void PlaneDetectorRos::checkFrameKnown(const sensor_msgs::PointCloud2ConstPtr& cloud)
{
  // Right after a tf reset every frame looks unknown for a moment: no verdict then.
  if (timeJumpedBack(cloud->header.stamp) || !frameUnknown(cloud->header.frame_id)) return;
  const auto lock = lockMap();
  ++frames_dropped_;
  ROS_WARN_THROTTLE_NAMED(5.0, name_, "Cloud skipped: no transform from '%s' to '%s': tf has never seen frame '%s'.",
                        cloud->header.frame_id.c_str(), world_frame_.c_str(), cloud->header.frame_id.c_str());
}

// A looping bag or a restarted simulator sends stamps back in time; tf's cache then holds
// the "future". Start tf afresh (a new listener gets the latched static transforms again)
// and keep the map: planes live in the world frame, not in time.
bool PlaneDetectorRos::timeJumpedBack(const ros::Time& stamp)
{
  double jump = 0.0;
  {
    const auto lock = lockMap();
    if (!last_arrival_stamp_.isZero() && stamp + ros::Duration(kTimeJumpTolerance) < last_arrival_stamp_)
    {
      jump = (last_arrival_stamp_ - stamp).toSec();
      ++time_jumps_back_;
    }
    last_arrival_stamp_ = stamp;
  }
  if (jump == 0.0) return false;
  ROS_WARN_THROTTLE_NAMED(5.0, name_, "Cloud stamps jumped back by %.3f s (a looping bag?): tf buffer cleared, the plane map kept.",
                        jump);
  // Not under map_mutex_: the listener's thread may be inside cloudCallback waiting for it.
  std::lock_guard<std::mutex> lock(tf_reset_mutex_);
  tf_listener_.reset();
  tf_buffer_->clear();
  tf_listener_.reset(new tf2_ros::TransformListener(*tf_buffer_));
  return true;
}

void PlaneDetectorRos::failureCallback(const sensor_msgs::PointCloud2ConstPtr& cloud,
                                     tf2_ros::filter_failure_reasons::FilterFailureReason reason)
{
  if (frameUnknown(cloud->header.frame_id)) return;  // counted and reported at arrival
  const auto lock = lockMap();
  ++frames_dropped_;
  ROS_WARN_THROTTLE_NAMED(5.0, name_, "Cloud skipped: no transform from '%s' to '%s' at %.3f (%s).",
                        cloud->header.frame_id.c_str(), world_frame_.c_str(), cloud->header.stamp.toSec(),
                        reason == tf2_ros::filter_failure_reasons::EmptyFrameID ? "empty frame_id" :
                        reason == tf2_ros::filter_failure_reasons::OutTheBack ? "older than the tf buffer" :
                                                                               "not available in time");
}

void PlaneDetectorRos::cloudCallback(const sensor_msgs::PointCloud2ConstPtr& cloud)
{
  Eigen::Isometry3d camera_to_world;
  try
  {
    camera_to_world = tf2::transformToEigen(
        tf_buffer_->lookupTransform(world_frame_, tf2FrameId(cloud->header.frame_id), cloud->header.stamp));
  }
  catch (const tf2::TransformException& e)
  {
    const auto lock = lockMap();
    ++frames_dropped_;
    ROS_WARN_THROTTLE_NAMED(5.0, name_, "Cloud skipped: %s", e.what());
    return;
  }
  // The message is read in place (float32 x/y/z) and never modified.
  CloudView view;
  std::vector<float> converted;
  std::string error;
  const bool viewable = makeCloudView(layoutOf(*cloud), view, converted, &error);

  const auto lock = lockMap();
  // The subscriber queue drops the oldest clouds when the detector falls behind; drivers
  // number their messages, so gaps in header.seq count them.
  if (last_seq_ != 0 && cloud->header.seq > last_seq_ + 1) frames_queue_dropped_ += cloud->header.seq - last_seq_ - 1;
  last_seq_ = cloud->header.seq;
  arrivals_.push_back(ros::WallTime::now());
  while (arrivals_.size() > 30) arrivals_.pop_front();
  if (!viewable || !detector_->processFrame(view, camera_to_world, cloud->header.stamp.toSec(), &error))
  {
    ++frames_rejected_;
    ROS_ERROR_THROTTLE_NAMED(5.0, name_, "Cloud from '%s' refused: %s", cloud->header.frame_id.c_str(), error.c_str());
    return;
  }
  ++frames_processed_;
  last_ms_ = detector_->lastTimings().total_ms;
  last_stamp_ = cloud->header.stamp;
  publishMap();
  if (segmented_pub_.getNumSubscribers() > 0 || inliers_pub_.getNumSubscribers() > 0) publishLabels(*cloud, view);
}

void PlaneDetectorRos::publishMap()
{
  std_msgs::Header header;
  header.frame_id = world_frame_;
  header.stamp = last_stamp_;
  PlaneArray::Ptr planes(new PlaneArray);
  planes->header = header;
  visualization_msgs::MarkerArray::Ptr markers(new visualization_msgs::MarkerArray);
  markers->markers.push_back(deleteAllMarker(header));
  for (const DetectedPlane& p : detector_->planes())
  {
    const std::vector<Eigen::Vector3d> hull = detector_->hull(p);
    // One pass over the extent's cells for both: each shape carries its region's hull.
    const std::vector<PlaneOutline> outlines = detector_->outlines(p);
    std::vector<std::vector<Eigen::Vector3d>> regions;
    for (const PlaneOutline& outline : outlines) regions.push_back(outline.hull);
    planes->planes.push_back(toPlaneMsg(p, hull, regions, outlines));
    appendPlaneMarkers(header, p, outlines, markers->markers);
  }
  planes_pub_.publish(planes);
  markers_pub_.publish(markers);
  ModelCoefficientsArray::Ptr coefficients(new ModelCoefficientsArray);
  fillModelCoefficients(header, detector_->planes(), *coefficients);
  coefficients_pub_.publish(coefficients);
}

// The frame's points by plane: the segmented cloud and the inliers (each only when subscribed).
void PlaneDetectorRos::publishLabels(const sensor_msgs::PointCloud2& cloud, const CloudView& view)
{
  std::vector<int> labels;
  detector_->labelPixels(view, labels);
  if (segmented_pub_.getNumSubscribers() > 0)
  {
    sensor_msgs::PointCloud2::Ptr out(new sensor_msgs::PointCloud2);
    fillSegmentedCloud(cloud.header, view, labels, *out);
    segmented_pub_.publish(out);
  }
  if (inliers_pub_.getNumSubscribers() > 0)
  {
    ClusterPointIndices::Ptr inliers(new ClusterPointIndices);
    fillClusterIndices(cloud.header, detector_->planes(), labels, *inliers);
    inliers_pub_.publish(inliers);
  }
}

void PlaneDetectorRos::reconfigure(HoughPlaneDetectorConfig& config, uint32_t /*level*/)
{
  const DetectorParams requested = toParams(config);
  const auto lock = lockMap();
  std::string problem;
  if (!requested.validate(&problem))
  {
    ROS_ERROR_NAMED(name_, "Reconfigure refused: %s; keeping the current parameters.", problem.c_str());
    config = toConfig(params_);
    return;
  }
  if (PlaneDetector::sameGrid(requested, params_))
  {
    std::string why;
    if (!detector_->updateParams(requested, &why))
    {
      ROS_ERROR_NAMED(name_, "Reconfigure refused by the detector: %s; keeping the current parameters.", why.c_str());
      config = toConfig(params_);
      return;
    }
  }
  else
  {
    ROS_WARN_NAMED(name_, "Hough grid reconfigured (resolution %d, angle_step %g, d_step %g): the map starts empty.",
                 requested.resolution, requested.effectiveAngleStep(), requested.effectiveDStep());
    detector_.reset(new PlaneDetector(requested));
    publishMap();
  }
  params_ = requested;
}

bool PlaneDetectorRos::resetService(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  const auto lock = lockMap();
  detector_->reset();
  publishMap();  // an empty array and a DELETEALL: no stale markers
  ROS_INFO_NAMED(name_, "Plane map reset.");
  return true;
}

bool PlaneDetectorRos::saveMapService(SaveMap::Request& req, SaveMap::Response& res)
{
  const auto lock = lockMap();
  std::string error;
  res.success = detector_->saveMap(req.path, &error);
  res.message = res.success ? "saved " + std::to_string(detector_->planes().size()) + " planes to " + req.path : error;
  if (res.success)
    ROS_INFO_NAMED(name_, "%s", res.message.c_str());
  else
    ROS_ERROR_NAMED(name_, "save_map failed: %s", res.message.c_str());
  return true;
}

bool PlaneDetectorRos::loadMapService(LoadMap::Request& req, LoadMap::Response& res)
{
  const auto lock = lockMap();
  std::string error;
  res.success = detector_->loadMap(req.path, &error);
  res.message = res.success ? "loaded " + std::to_string(detector_->planes().size()) + " planes from " + req.path
                            : error + "; the current map is kept";
  if (res.success)
    ROS_INFO_NAMED(name_, "%s", res.message.c_str());
  else
    ROS_ERROR_NAMED(name_, "load_map refused: %s", res.message.c_str());
  if (res.success) publishMap();
  return true;
}

void PlaneDetectorRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status)
{
  const auto lock = lockMap();
  const MemoryReport memory = detector_->memory();
  double rate = 0.0;
  if (arrivals_.size() >= 2)
    rate = (arrivals_.size() - 1) / std::max(1e-6, (arrivals_.back() - arrivals_.front()).toSec());
  if (frames_processed_ == 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no cloud processed yet");
  else if (memory.chunks_evicted_total > 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "the max_chunks cap freed Hough chunks");
  else if (detector_->lastStats().votes_out_of_range > 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "planes beyond max_distance are not represented");
  else if (frames_dropped_ + frames_rejected_ + frames_queue_dropped_ > 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "some clouds were skipped");
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "ok");
  status.add("input rate (Hz)", rate);
  status.add("ms per frame (last)", last_ms_);
  status.add("frames processed", frames_processed_);
  status.add("frames skipped (no transform)", frames_dropped_);
  status.add("frames dropped (queue full, detector behind)", frames_queue_dropped_);
  status.add("frames refused (bad cloud)", frames_rejected_);
  status.add("time jumps back (tf reset)", time_jumps_back_);
  status.add("planes", detector_->planes().size());
  status.add("Hough space MB", memory.global_bytes / 1e6);
  status.add("Hough space % of dense", 100.0 * memory.global_bytes / std::max<size_t>(1, memory.dense_bytes));
  status.add("Hough chunks", memory.global_chunks);
  status.add("per-frame Hough space MB (with its reuse pool)", (memory.local_bytes + memory.local_pooled_bytes) / 1e6);
  status.add("Hough chunks freed by max_chunks", memory.chunks_evicted_total);
  status.add("votes beyond max_distance (last frame)", detector_->lastStats().votes_out_of_range);
  const HoughParameterization& grid = detector_->parameterization();
  status.addf("Hough grid", "resolution %d: %d x %d x %d cells", params_.resolution, grid.sizeAngle(), grid.sizeAngle(),
              grid.sizeD());
}

}  // namespace hough_plane_detector
