#include "hough_plane_detector/ros/plane_markers.h"

#include <unordered_map>

#include <cmath>
#include <cstring>

#include <sensor_msgs/point_cloud2_iterator.h>

namespace hough_plane_detector
{

namespace
{
geometry_msgs::Polygon toPolygon(const std::vector<Eigen::Vector3d>& vertices)
{
  geometry_msgs::Polygon polygon;
  for (const Eigen::Vector3d& v : vertices)
  {
    geometry_msgs::Point32 q;
    q.x = static_cast<float>(v.x());
    q.y = static_cast<float>(v.y());
    q.z = static_cast<float>(v.z());
    polygon.points.push_back(q);
  }
  return polygon;
}
}  // namespace

Plane toPlaneMsg(const DetectedPlane& plane, const std::vector<Eigen::Vector3d>& hull,
                 const std::vector<std::vector<Eigen::Vector3d>>& regions, const std::vector<PlaneOutline>& outlines)
{
  Plane msg;
  msg.id = plane.id;
  msg.coef.coef = {plane.normal.x(), plane.normal.y(), plane.normal.z(), plane.d};
  msg.normal.x = plane.normal.x();
  msg.normal.y = plane.normal.y();
  msg.normal.z = plane.normal.z();
  msg.d = plane.d;
  msg.strength = plane.strength;
  msg.support = static_cast<uint32_t>(plane.support);
  msg.confirmations = static_cast<uint32_t>(plane.confirmations);
  msg.contradictions = static_cast<uint32_t>(plane.contradictions);
  msg.first_seen.fromSec(plane.first_seen);
  msg.last_seen.fromSec(plane.last_seen);
  msg.hull = toPolygon(hull);
  for (const auto& region : regions) msg.regions.push_back(toPolygon(region));
  for (const PlaneOutline& outline : outlines)
  {
    PlaneShape shape;
    shape.outline = toPolygon(outline.boundary);
    for (const auto& hole : outline.holes) shape.holes.push_back(toPolygon(hole));
    shape.area = outline.area;
    msg.outlines.push_back(shape);
  }
  return msg;
}

std_msgs::ColorRGBA colourForId(int id, float alpha)
{
  const double hue = std::fmod(0.13 + 0.618033988749895 * id, 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(hue))
  {
    case 0: r = 1; g = x; break;
    case 1: r = x; g = 1; break;
    case 2: g = 1; b = x; break;
    case 3: g = x; b = 1; break;
    case 4: r = x; b = 1; break;
    default: r = 1; b = x; break;
  }
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(0.15 + 0.85 * r);
  c.g = static_cast<float>(0.15 + 0.85 * g);
  c.b = static_cast<float>(0.15 + 0.85 * b);
  c.a = alpha;
  return c;
}

visualization_msgs::Marker deleteAllMarker(const std_msgs::Header& header)
{
  visualization_msgs::Marker m;
  m.header = header;
  m.action = visualization_msgs::Marker::DELETEALL;
  return m;
}

namespace
{
geometry_msgs::Point toPoint(const Eigen::Vector3d& v)
{
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}

visualization_msgs::Marker baseMarker(const std_msgs::Header& header, const char* ns, int id, int type)
{
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  return m;
}
}  // namespace

void appendPlaneMarkers(const std_msgs::Header& header, const DetectedPlane& plane, const std::vector<PlaneOutline>& outlines,
                        std::vector<visualization_msgs::Marker>& markers)
{
  if (outlines.empty() || outlines.front().boundary.size() < 3) return;  // not seen enough yet to have an extent
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // of the largest region's outline
  for (const auto& v : outlines.front().boundary) centre += v;
  centre /= static_cast<double>(outlines.front().boundary.size());

  // One patch and one outline marker per plane, covering all its regions: the regions' rows of
  // cells as quads (holes stay open), their outlines and holes as lines.
  visualization_msgs::Marker patch = baseMarker(header, "patches", plane.id, visualization_msgs::Marker::TRIANGLE_LIST);
  patch.color = colourForId(plane.id, 0.45f);
  visualization_msgs::Marker outline = baseMarker(header, "outlines", plane.id, visualization_msgs::Marker::LINE_LIST);
  outline.scale.x = 0.02;
  outline.color = colourForId(plane.id, 1.0f);
  auto addLoop = [&](const std::vector<Eigen::Vector3d>& loop) {
    for (size_t i = 0; i < loop.size(); ++i)
    {
      outline.points.push_back(toPoint(loop[i]));
      outline.points.push_back(toPoint(loop[(i + 1) % loop.size()]));
    }
  };
  for (const PlaneOutline& region : outlines)
  {
    for (const auto& quad : region.fill)
      for (int corner : {0, 1, 2, 0, 2, 3}) patch.points.push_back(toPoint(quad[corner]));
    addLoop(region.boundary);
    for (const auto& hole : region.holes) addLoop(hole);
  }
  markers.push_back(patch);
  markers.push_back(outline);

  visualization_msgs::Marker arrow = baseMarker(header, "normals", plane.id, visualization_msgs::Marker::ARROW);
  arrow.scale.x = 0.03;
  arrow.scale.y = 0.06;
  arrow.scale.z = 0.08;
  arrow.color = colourForId(plane.id, 1.0f);
  arrow.points.push_back(toPoint(centre));
  arrow.points.push_back(toPoint(centre + 0.3 * plane.normal));
  markers.push_back(arrow);

  visualization_msgs::Marker label = baseMarker(header, "labels", plane.id, visualization_msgs::Marker::TEXT_VIEW_FACING);
  label.pose.position = toPoint(centre + 0.35 * plane.normal);
  label.scale.z = 0.2;
  label.color = colourForId(plane.id, 1.0f);
  label.text = std::to_string(plane.id);
  markers.push_back(label);
}

void fillSegmentedCloud(const std_msgs::Header& header, const CloudView& view, const std::vector<int>& labels,
                        sensor_msgs::PointCloud2& out)
{
  out.header = header;
  sensor_msgs::PointCloud2Modifier modifier(out);
  modifier.setPointCloud2Fields(5, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                                "z", 1, sensor_msgs::PointField::FLOAT32, "rgb", 1, sensor_msgs::PointField::FLOAT32,
                                "label", 1, sensor_msgs::PointField::UINT32);
  out.height = view.height;
  out.width = view.width;
  modifier.resize(static_cast<size_t>(view.width) * view.height);
  out.height = view.height;
  out.width = view.width;
  out.row_step = out.point_step * out.width;
  out.is_dense = false;
  sensor_msgs::PointCloud2Iterator<float> x(out, "x"), rgb(out, "rgb");
  // uint32 like PCL's PointXYZRGBL label, so pcl::fromROSMsg keeps it; no plane is kNoPlaneLabel.
  sensor_msgs::PointCloud2Iterator<uint32_t> label(out, "label");
  for (int v = 0; v < view.height; ++v)
    for (int u = 0; u < view.width; ++u, ++x, ++rgb, ++label)
    {
      view.point(u, v, x[0], x[1], x[2]);
      const int id = labels[static_cast<size_t>(v) * view.width + u];
      *label = id >= 0 ? static_cast<uint32_t>(id) : kNoPlaneLabel;
      uint8_t r = 128, g = 128, b = 128;  // grey: on no plane
      if (id >= 0)
      {
        const std_msgs::ColorRGBA c = colourForId(id, 1.0f);
        r = static_cast<uint8_t>(255 * c.r);
        g = static_cast<uint8_t>(255 * c.g);
        b = static_cast<uint8_t>(255 * c.b);
      }
      const uint32_t packed = (static_cast<uint32_t>(r) << 16) | (static_cast<uint32_t>(g) << 8) | b;
      std::memcpy(&*rgb, &packed, sizeof(float));
    }
}

void fillModelCoefficients(const std_msgs::Header& header, const std::vector<DetectedPlane>& planes,
                           ModelCoefficientsArray& out)
{
  out.header = header;
  out.coefficients.resize(planes.size());
  for (size_t i = 0; i < planes.size(); ++i)
  {
    const DetectedPlane& p = planes[i];
    out.coefficients[i].header = header;
    out.coefficients[i].values = {static_cast<float>(p.normal.x()), static_cast<float>(p.normal.y()),
                                  static_cast<float>(p.normal.z()), static_cast<float>(p.d)};
  }
}

void fillClusterIndices(const std_msgs::Header& header, const std::vector<DetectedPlane>& planes,
                        const std::vector<int>& labels, ClusterPointIndices& out)
{
  out.header = header;
  out.cluster_indices.resize(planes.size());
  std::unordered_map<int, size_t> slot;  // plane id -> position in `planes`
  for (size_t i = 0; i < planes.size(); ++i)
  {
    slot[planes[i].id] = i;
    out.cluster_indices[i].header = header;
    out.cluster_indices[i].indices.clear();
  }
  for (size_t pixel = 0; pixel < labels.size(); ++pixel)
  {
    if (labels[pixel] < 0) continue;
    const auto it = slot.find(labels[pixel]);
    if (it != slot.end()) out.cluster_indices[it->second].indices.push_back(static_cast<int32_t>(pixel));
  }
}

}  // namespace hough_plane_detector
