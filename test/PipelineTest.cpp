// Integration: the detector nodelet fed by the simulated Kinect in a real nodelet manager.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl_conversions/pcl_conversions.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <visualization_msgs/MarkerArray.h>

#include "hough_plane_detector/ClusterPointIndices.h"
#include "hough_plane_detector/LoadMap.h"
#include "hough_plane_detector/ModelCoefficientsArray.h"
#include "hough_plane_detector/PlaneArray.h"
#include "hough_plane_detector/SaveMap.h"
#include "hough_plane_detector/sim/scene_renderer.h"
#include "reconfigure_request.h"

using namespace hough_plane_detector;

namespace
{
const std::string kNode = "/hough_plane_detector";

class Listener
{
public:
  Listener()
  {
    ros::NodeHandle nh;
    planes_sub_ = nh.subscribe<PlaneArray>(kNode + "/planes", 10, [this](const PlaneArray::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      planes_.push_back(m);
      changed_.notify_all();
    });
    markers_sub_ = nh.subscribe<visualization_msgs::MarkerArray>(kNode + "/markers", 10,
                                                                  [this](const visualization_msgs::MarkerArray::ConstPtr& m) {
                                                                    std::lock_guard<std::mutex> lock(mutex_);
                                                                    markers_.push_back(m);
                                                                    changed_.notify_all();
                                                                  });
    diagnostics_sub_ = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 10, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          diagnostics_.push_back(m);
          changed_.notify_all();
        });
  }

  // Waits until `done` holds on the received messages (checked under the lock) or times out.
  bool waitFor(double seconds, const std::function<bool()>& done)
  {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
    std::unique_lock<std::mutex> lock(mutex_);
    while (!done())
    {
      if (ros::WallTime::now() > end) return false;
      changed_.wait_for(lock, std::chrono::milliseconds(100));
    }
    return true;
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<PlaneArray::ConstPtr> planes_;
  std::vector<visualization_msgs::MarkerArray::ConstPtr> markers_;
  std::vector<diagnostic_msgs::DiagnosticArray::ConstPtr> diagnostics_;

private:
  ros::Subscriber planes_sub_, markers_sub_, diagnostics_sub_;
};

Listener* listener = nullptr;

const Plane* findPlane(const PlaneArray& array, const TruePlane& truth, double angle_tol, double d_tol)
{
  for (const Plane& p : array.planes)
  {
    const Eigen::Vector3d n(p.normal.x, p.normal.y, p.normal.z);
    const double sign = n.dot(truth.normal) >= 0 ? 1.0 : -1.0;
    if (std::acos(std::min(1.0, std::abs(n.dot(truth.normal)))) <= angle_tol && std::abs(sign * p.d - truth.d) <= d_tol)
      return &p;
  }
  return nullptr;
}

bool hasRoomPlanes(const PlaneArray& array, double angle_tol, double d_tol)
{
  for (const TruePlane& t : makeOfficeRoom().truePlanes())
    if ((t.name == "floor" || t.name.rfind("wall_", 0) == 0) && !findPlane(array, t, angle_tol, d_tol)) return false;
  return true;
}

}  // namespace

TEST(Pipeline, FindsTheRoomsPlanesWithExtentsAndMarkers)
{
  ros::NodeHandle private_nh("~");
  const double angle_tol = private_nh.param("angle_tolerance", 0.01), d_tol = private_nh.param("distance_tolerance", 0.02);
  // One lap of the simulated tour is 12 s at 10 Hz.
  ASSERT_TRUE(listener->waitFor(90.0, [&] {
    return !listener->planes_.empty() && hasRoomPlanes(*listener->planes_.back(), angle_tol, d_tol);
  })) << "floor and four walls not all found within 0.01 rad / 2 cm";
  std::lock_guard<std::mutex> lock(listener->mutex_);
  const PlaneArray& last = *listener->planes_.back();
  EXPECT_EQ(last.header.frame_id, "odom");
  for (const Plane& p : last.planes)
  {
    EXPECT_NEAR(std::sqrt(p.normal.x * p.normal.x + p.normal.y * p.normal.y + p.normal.z * p.normal.z), 1.0, 1e-6);
    EXPECT_EQ(p.coef.coef[3], p.d);
  }
  for (const TruePlane& t : makeOfficeRoom().truePlanes())
  {
    if (t.name != "floor") continue;
    const Plane* floor = findPlane(last, t, angle_tol, d_tol);
    ASSERT_NE(floor, nullptr);
    EXPECT_GE(floor->hull.points.size(), 3u) << "the floor has a bounded patch";
    for (const auto& q : floor->hull.points)
    {
      EXPECT_NEAR(q.z, 0.0, 0.03);
      EXPECT_LE(std::abs(q.x), 3.1);
      EXPECT_LE(std::abs(q.y), 2.6);
    }
  }
  ASSERT_FALSE(listener->markers_.empty());
  const auto& markers = listener->markers_.back()->markers;
  ASSERT_FALSE(markers.empty());
  EXPECT_EQ(markers.front().action, visualization_msgs::Marker::DELETEALL);
  int patches = 0;
  for (const auto& m : markers) patches += m.ns == "patches" && m.type == visualization_msgs::Marker::TRIANGLE_LIST;
  EXPECT_GE(patches, 5);
}

// A map server's outputs are latched by default, so rviz or a node started later gets the map.
TEST(Pipeline, PlanesAndMarkersAreLatched)
{
  ros::NodeHandle nh;
  std::mutex mutex;
  std::condition_variable received;
  std::map<std::string, std::string> latching;  // topic -> the publisher's "latching" header
  auto remember = [&](const std::string& topic, const ros::M_string& header) {
    std::lock_guard<std::mutex> lock(mutex);
    const auto it = header.find("latching");
    latching[topic] = it == header.end() ? "" : it->second;
    received.notify_all();
  };
  const boost::function<void(const ros::MessageEvent<PlaneArray const>&)> on_planes =
      [&](const ros::MessageEvent<PlaneArray const>& e) { remember("planes", e.getConnectionHeader()); };
  const boost::function<void(const ros::MessageEvent<visualization_msgs::MarkerArray const>&)> on_markers =
      [&](const ros::MessageEvent<visualization_msgs::MarkerArray const>& e) { remember("markers", e.getConnectionHeader()); };
  const ros::Subscriber planes = nh.subscribe<const ros::MessageEvent<PlaneArray const>&>(kNode + "/planes", 1, on_planes);
  const ros::Subscriber markers =
      nh.subscribe<const ros::MessageEvent<visualization_msgs::MarkerArray const>&>(kNode + "/markers", 1, on_markers);
  std::unique_lock<std::mutex> lock(mutex);
  ASSERT_TRUE(received.wait_for(lock, std::chrono::seconds(30), [&] { return latching.size() == 2; }));
  EXPECT_EQ(latching["planes"], "1");
  EXPECT_EQ(latching["markers"], "1");
}

// What other ROS tools read: the segmented cloud through PCL's PointXYZRGBL (uint32 label),
// ~coefficients as pcl_msgs/ModelCoefficients and ~inliers as pcl_msgs/PointIndices, one per
// map plane in the order of ~planes; for one frame the inliers are exactly the points the
// segmented cloud labels with that plane.
TEST(Pipeline, PclOutputsMatchThePlanesAndTheSegmentedCloud)
{
  ros::NodeHandle nh;
  std::mutex mutex;
  std::condition_variable received;
  std::map<double, sensor_msgs::PointCloud2::ConstPtr> segmented;
  std::map<double, ClusterPointIndices::ConstPtr> inliers;
  std::map<double, ModelCoefficientsArray::ConstPtr> coefficients;
  std::map<double, PlaneArray::ConstPtr> planes;
  auto keep = [&](auto& into, const auto& message) {
    std::lock_guard<std::mutex> lock(mutex);
    into[message->header.stamp.toSec()] = message;
    received.notify_all();
  };
  const ros::Subscriber s1 = nh.subscribe<sensor_msgs::PointCloud2>(
      kNode + "/segmented_cloud", 5, [&](const sensor_msgs::PointCloud2::ConstPtr& m) { keep(segmented, m); });
  const ros::Subscriber s2 = nh.subscribe<ClusterPointIndices>(
      kNode + "/inliers", 5, [&](const ClusterPointIndices::ConstPtr& m) { keep(inliers, m); });
  const ros::Subscriber s3 = nh.subscribe<ModelCoefficientsArray>(
      kNode + "/coefficients", 5, [&](const ModelCoefficientsArray::ConstPtr& m) { keep(coefficients, m); });
  const ros::Subscriber s4 =
      nh.subscribe<PlaneArray>(kNode + "/planes", 5, [&](const PlaneArray::ConstPtr& m) { keep(planes, m); });
  // One frame whose four messages all arrived and whose map has planes.
  double stamp = -1.0;
  std::unique_lock<std::mutex> lock(mutex);
  ASSERT_TRUE(received.wait_for(lock, std::chrono::seconds(90), [&] {
    for (const auto& entry : segmented)
      if (inliers.count(entry.first) && coefficients.count(entry.first) && planes.count(entry.first) &&
          planes[entry.first]->planes.size() >= 3)
      {
        stamp = entry.first;
        return true;
      }
    return false;
  }));
  const PlaneArray& map = *planes[stamp];
  const ModelCoefficientsArray& model = *coefficients[stamp];
  const ClusterPointIndices& indices = *inliers[stamp];
  pcl::PointCloud<pcl::PointXYZRGBL> cloud;
  pcl::fromROSMsg(*segmented[stamp], cloud);
  lock.unlock();
  ASSERT_EQ(cloud.width, 640u);
  ASSERT_EQ(cloud.height, 480u);
  ASSERT_EQ(model.coefficients.size(), map.planes.size());
  ASSERT_EQ(indices.cluster_indices.size(), map.planes.size());
  EXPECT_EQ(model.header.frame_id, map.header.frame_id);
  EXPECT_EQ(indices.header.frame_id, segmented[stamp]->header.frame_id);
  std::map<uint32_t, size_t> labelled;  // plane id -> points the PCL cloud labels with it
  for (const pcl::PointXYZRGBL& p : cloud.points) ++labelled[p.label];
  size_t on_planes = 0;
  for (size_t i = 0; i < map.planes.size(); ++i)
  {
    const Plane& plane = map.planes[i];
    ASSERT_EQ(model.coefficients[i].values.size(), 4u);
    EXPECT_NEAR(model.coefficients[i].values[0], plane.normal.x, 1e-6);
    EXPECT_NEAR(model.coefficients[i].values[1], plane.normal.y, 1e-6);
    EXPECT_NEAR(model.coefficients[i].values[2], plane.normal.z, 1e-6);
    EXPECT_NEAR(model.coefficients[i].values[3], plane.d, 1e-5);
    const std::vector<int32_t>& on_plane = indices.cluster_indices[i].indices;
    EXPECT_EQ(on_plane.size(), labelled[static_cast<uint32_t>(plane.id)]) << "plane " << plane.id;
    for (int32_t index : on_plane)
    {
      ASSERT_LT(static_cast<size_t>(index), cloud.points.size());
      ASSERT_EQ(cloud.points[index].label, static_cast<uint32_t>(plane.id));
    }
    on_planes += on_plane.size();
  }
  EXPECT_GT(on_planes, 100000u) << "a room's floor and walls fill most of a VGA frame";
}

TEST(Pipeline, ResetClearsPlanesAndMarkers)
{
  ASSERT_TRUE(listener->waitFor(90.0, [&] { return !listener->planes_.empty() && !listener->planes_.back()->planes.empty(); }));
  size_t planes_seen, markers_seen;
  {
    std::lock_guard<std::mutex> lock(listener->mutex_);
    planes_seen = listener->planes_.size();
    markers_seen = listener->markers_.size();
  }
  call(kNode + "/reset", std_srvs::Empty());
  EXPECT_TRUE(listener->waitFor(5.0, [&] {
    for (size_t i = planes_seen; i < listener->planes_.size(); ++i)
      if (listener->planes_[i]->planes.empty()) return true;
    return false;
  })) << "no empty plane array after reset";
  EXPECT_TRUE(listener->waitFor(5.0, [&] {
    for (size_t i = markers_seen; i < listener->markers_.size(); ++i)
    {
      const auto& m = listener->markers_[i]->markers;
      if (m.size() == 1 && m[0].action == visualization_msgs::Marker::DELETEALL) return true;
    }
    return false;
  })) << "no marker array that only clears after reset";
}

TEST(Pipeline, SaveResetLoadRestoresTheMap)
{
  ros::NodeHandle private_nh("~");
  const double angle_tol = private_nh.param("angle_tolerance", 0.01), d_tol = private_nh.param("distance_tolerance", 0.02);
  ASSERT_TRUE(listener->waitFor(90.0, [&] {
    return !listener->planes_.empty() && hasRoomPlanes(*listener->planes_.back(), angle_tol, d_tol);
  }));
  const std::string path = "/tmp/hough_plane_detector_pipeline_test.map";
  SaveMap save;
  save.request.path = path;
  save = call(kNode + "/save_map", save);
  ASSERT_TRUE(save.response.success) << save.response.message;

  // The file holds the map as it was at the save: load it into the running node after a reset.
  call(kNode + "/reset", std_srvs::Empty());
  size_t seen;
  {
    std::lock_guard<std::mutex> lock(listener->mutex_);
    seen = listener->planes_.size();
  }
  LoadMap load;
  load.request.path = path;
  load = call(kNode + "/load_map", load);
  ASSERT_TRUE(load.response.success) << load.response.message;
  // load_map publishes the restored map at once, before the next frame could rebuild it.
  ASSERT_TRUE(listener->waitFor(5.0, [&] {
    for (size_t i = seen; i < listener->planes_.size(); ++i)
      if (hasRoomPlanes(*listener->planes_[i], angle_tol, d_tol) && listener->planes_[i]->planes.size() >= 5) return true;
    return false;
  })) << "the loaded map does not hold the room's planes";

  // A missing or foreign file is refused and the map stays.
  load.request.path = "/tmp/does-not-exist.map";
  load = call(kNode + "/load_map", load);
  EXPECT_FALSE(load.response.success);
  EXPECT_NE(load.response.message.find("cannot open"), std::string::npos) << load.response.message;
  std::ofstream("/tmp/hough_plane_detector_foreign.map") << "not a map";
  load.request.path = "/tmp/hough_plane_detector_foreign.map";
  load = call(kNode + "/load_map", load);
  EXPECT_FALSE(load.response.success);
  EXPECT_NE(load.response.message.find("not a hough_plane_detector map"), std::string::npos) << load.response.message;
}

TEST(Pipeline, ReconfiguringTheResolutionRebuildsTheSpaceAndBadValuesAreRefused)
{
  const dynamic_reconfigure::Reconfigure srv = call(kNode + "/set_parameters", setInt("resolution", 512));
  bool applied = false;
  for (const auto& p : srv.response.config.ints) applied = applied || (p.name == "resolution" && p.value == 512);
  EXPECT_TRUE(applied);
  EXPECT_TRUE(listener->waitFor(10.0, [&] {
    if (listener->diagnostics_.empty()) return false;
    for (const auto& status : listener->diagnostics_.back()->status)
      for (const auto& kv : status.values)
        if (kv.key == "Hough grid" && kv.value.rfind("resolution 512:", 0) == 0) return true;
    return false;
  })) << "diagnostics never showed the 512 grid";

  // A window that is not a multiple of the stride is refused: the server answers with the old value.
  const dynamic_reconfigure::Reconfigure bad = call(kNode + "/set_parameters", setInt("normal_window", 12));
  for (const auto& p : bad.response.config.ints)
    if (p.name == "normal_window") { EXPECT_EQ(p.value, 32); }
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_pipeline");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  Listener l;
  listener = &l;
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
