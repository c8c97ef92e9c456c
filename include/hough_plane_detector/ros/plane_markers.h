// The plane map as messages: Plane, RViz markers, the segmented cloud and the pcl_msgs outputs.
#pragma once

#include <cstdint>

#include <vector>

#include <Eigen/Core>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/Marker.h>

#include "hough_plane_detector/ClusterPointIndices.h"
#include "hough_plane_detector/ModelCoefficientsArray.h"
#include "hough_plane_detector/Plane.h"
#include "hough_plane_detector/core/plane_detector.h"

namespace hough_plane_detector
{

// A map plane with its extent's hull and regions (world frame) as a Plane message.
Plane toPlaneMsg(const DetectedPlane& plane, const std::vector<Eigen::Vector3d>& hull,
                 const std::vector<std::vector<Eigen::Vector3d>>& regions, const std::vector<PlaneOutline>& outlines);
// A stable, well-spread colour per plane id (golden-ratio hues).
std_msgs::ColorRGBA colourForId(int id, float alpha);
// DELETEALL, sent first in every array so that no marker of a vanished plane stays.
visualization_msgs::Marker deleteAllMarker(const std_msgs::Header& header);
// Per plane: its regions filled (TRIANGLE_LIST, ns "patches"; holes left open), their outlines
// and holes (LINE_LIST, "outlines"), normal (ARROW, "normals") and id label (TEXT_VIEW_FACING,
// "labels") at its largest region; marker id = plane id.
void appendPlaneMarkers(const std_msgs::Header& header, const DetectedPlane& plane, const std::vector<PlaneOutline>& outlines,
                        std::vector<visualization_msgs::Marker>& markers);
// Label of a point on no plane in the segmented cloud (uint32, as PCL's PointXYZRGBL).
constexpr uint32_t kNoPlaneLabel = 0xFFFFFFFFu;
// x y z of the frame plus rgb and label (uint32 plane id, kNoPlaneLabel for none) per point.
void fillSegmentedCloud(const std_msgs::Header& header, const CloudView& view, const std::vector<int>& labels,
                        sensor_msgs::PointCloud2& out);
// Each plane's [a, b, c, d] in the order of `planes`.
void fillModelCoefficients(const std_msgs::Header& header, const std::vector<DetectedPlane>& planes,
                           ModelCoefficientsArray& out);
// Each plane's pixel indices (labels: the plane id of every pixel, -1 for none), in the order of
// `planes`; a plane with no point in the frame gets an empty list.
void fillClusterIndices(const std_msgs::Header& header, const std::vector<DetectedPlane>& planes,
                        const std::vector<int>& labels, ClusterPointIndices& out);

}  // namespace hough_plane_detector
