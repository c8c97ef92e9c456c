#include "osd_learn.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <set>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/core/plane_geometry.h"
#include "hough_plane_detector/tools/png_image.h"
#include "pcl_comparators.h"
#include "stopwatch.h"

namespace hough_plane_detector
{

namespace
{
constexpr double kMatchAngle = 0.06;      // rad, the data set's protocol
constexpr double kMatchDistance = 0.03;   // m
constexpr int kPclMinInliers = 1500;      // as the data set's README measured PCL
constexpr int kCopies = 5;                // a still camera: the same frame five times
constexpr int kFirstCurvedFrame = 33;     // learn33-44 hold cans and mugs

struct Entry
{
  std::string name;
  Eigen::Vector3d normal;
  double d;
  int points;
  int object;  // 0 for the table, else the object's label / 10 (obj20 -> 2)
  int box[4];  // x0, y0, x1, y1 of its pixels
};

bool matches(const Eigen::Vector3d& n, double d, const Entry& e, double* angle = nullptr, double* distance = nullptr)
{
  const double sign = n.dot(e.normal) >= 0.0 ? 1.0 : -1.0;
  const double a = std::acos(std::min(1.0, std::abs(n.dot(e.normal))));
  const double dd = std::abs(sign * d - e.d);
  if (angle) *angle = a;
  if (distance) *distance = dd;
  return a <= kMatchAngle && dd <= kMatchDistance;
}

// Scores one frame's detections: found entries (with their errors), duplicates, unmatched;
// `duplicate_of` receives, per detection, the entry it duplicates, else -1.
void score(const std::vector<Entry>& entries, const std::vector<Eigen::Vector4d>& detections, OsdMethodResult& result,
           std::vector<bool>* found_out = nullptr, std::vector<double>* angle_out = nullptr,
           std::vector<int>* duplicate_of = nullptr, std::vector<Eigen::Vector3d>* normal_out = nullptr)
{
  if (normal_out) normal_out->assign(entries.size(), Eigen::Vector3d::Zero());
  if (duplicate_of) duplicate_of->assign(detections.size(), -1);
  std::vector<int> matched(entries.size(), 0);
  std::vector<double> best_angle(entries.size(), 1e9), best_d(entries.size(), 1e9);
  for (const Eigen::Vector4d& p : detections)
  {
    const Eigen::Vector3d n = p.head<3>().normalized();
    const double d = p(3) / p.head<3>().norm();
    // A detection counts for the entry it fits best (box faces a few cm apart stay apart).
    int best = -1;
    double best_cost = 1e9;
    for (size_t i = 0; i < entries.size(); ++i)
    {
      double a, dd;
      if (!matches(n, d, entries[i], &a, &dd)) continue;
      const double cost = a / kMatchAngle + dd / kMatchDistance;
      if (cost < best_cost)
      {
        best_cost = cost;
        best = static_cast<int>(i);
      }
    }
    ++result.detections;
    if (best < 0)
    {
      ++result.unmatched;
      continue;
    }
    if (matched[best]++ > 0)
    {
      ++result.duplicates;
      if (duplicate_of) (*duplicate_of)[&p - detections.data()] = best;
    }
    double a, dd;
    matches(n, d, entries[best], &a, &dd);
    if (a + dd < best_angle[best] + best_d[best])
    {
      best_angle[best] = a;
      best_d[best] = dd;
      if (normal_out) (*normal_out)[best] = n;
    }
  }
  result.entries += static_cast<int>(entries.size());
  ++result.frames;
  for (size_t i = 0; i < entries.size(); ++i)
    if (matched[i])
    {
      ++result.found;
      result.angle_errors.push_back(best_angle[i]);
      result.d_errors.push_back(best_d[i]);
    }
  if (found_out)
  {
    found_out->assign(entries.size(), false);
    for (size_t i = 0; i < entries.size(); ++i) (*found_out)[i] = matched[i] > 0;
  }
  if (angle_out) *angle_out = best_angle;
}

std::vector<Eigen::Vector4d> mapPlanes(const PlaneDetector& detector)
{
  std::vector<Eigen::Vector4d> out;
  for (const DetectedPlane& p : detector.planes()) out.emplace_back(p.normal.x(), p.normal.y(), p.normal.z(), p.d);
  return out;
}

// What became of the candidate nearest to a missed entry in our detector's last frame;
// `nearest_offsets` receives how far that candidate lies from the entry.
std::string missReason(const PlaneDetector& detector, const Entry& entry, std::string* nearest_offsets)
{
  const PlaneCandidate* nearest = nullptr;
  double nearest_cost = 1e9, nearest_angle = 0.0, nearest_offset = 0.0;
  for (const PlaneCandidate& c : detector.lastCandidates())
  {
    double a, dd;
    matches(c.normal, c.d, entry, &a, &dd);
    const double cost = a / kMatchAngle + dd / kMatchDistance;
    if (cost < nearest_cost)
    {
      nearest_cost = cost;
      nearest = &c;
      nearest_angle = a;
      nearest_offset = dd;
    }
  }
  if (nearest)
  {
    char offsets[64];
    std::snprintf(offsets, sizeof(offsets), "%.3f rad, %.1f mm", nearest_angle, 1000.0 * nearest_offset);
    *nearest_offsets = offsets;
  }
  if (!nearest || nearest_cost > 4.0) return "no Hough peak near it";
  std::string reason = toString(nearest->verdict);
  if (nearest_cost > 2.0) return "nearest peak far off (" + reason + ")";
  if (nearest->verdict != CandidateVerdict::kAccepted) return reason;
  if (!matches(nearest->normal, nearest->d, entry)) return "accepted, fitted beyond the tolerance";
  // A map plane that matches it but counted for an entry it fits better: one plane for both.
  for (const DetectedPlane& plane : detector.planes())
    if (matches(plane.normal, plane.d, entry)) return "accepted, one map plane with another entry";
  // Why the map did not report it at first sight: how the frame's plane on it voted.
  const FirstSight* first_sight = nearestFirstSight(detector, [&](const Eigen::Vector3d& n, double d) {
    double a, dd;
    return matches(n, d, entry, &a, &dd) ? a / kMatchAngle + dd / kMatchDistance : -1.0;
  });
  return first_sight ? std::string("accepted, not in the map: ") + toString(*first_sight) : "accepted, not in the map";
}

// Least-squares normal of the masked pixels; false with fewer than min_pixels of them.
bool maskedPlaneNormal(const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, const std::vector<char>& mask, int min_pixels,
                       Eigen::Vector3d& normal)
{
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d squares = Eigen::Matrix3d::Zero();
  int count = 0;
  for (size_t i = 0; i < mask.size(); ++i)
  {
    if (!mask[i]) continue;
    const pcl::PointXYZRGBL& q = cloud.points[i];
    const Eigen::Vector3d x(q.x, q.y, q.z);
    sum += x;
    squares += x * x.transpose();
    ++count;
  }
  if (count < min_pixels) return false;
  const Eigen::Vector3d mean = sum / count;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(squares / count - mean * mean.transpose());
  normal = solver.eigenvectors().col(0);
  return true;
}

// For each found entry: our matching plane's error and that of the least-squares plane of
// the pixels we label with it (the table anywhere, a face inside its box with a margin).
// The map plane that matches the entry best (the scoring's cost), or nullptr.
const DetectedPlane* bestMatchingPlane(const PlaneDetector& detector, const Entry& e)
{
  const DetectedPlane* best = nullptr;
  double best_cost = 1e9, a, dd;
  for (const DetectedPlane& p : detector.planes())
    if (matches(p.normal, p.d, e, &a, &dd) && a / kMatchAngle + dd / kMatchDistance < best_cost)
    {
      best_cost = a / kMatchAngle + dd / kMatchDistance;
      best = &p;
    }
  return best;
}

// Whether a point lies on the entry's face: on its object (the table: labels 1-9) and within
// the annotation's 6 mm of its plane.
constexpr double kAnnotationBand = 0.006;  // m, the annotation's RANSAC distance
bool onEntryFace(const pcl::PointXYZRGBL& q, const Entry& e)
{
  const bool on_object =
      e.object == 0 ? q.label >= 1 && q.label <= 9 : q.label >= 20 && static_cast<int>(q.label / 10) == e.object;
  return on_object && std::isfinite(q.z) &&
         std::abs(e.normal.dot(Eigen::Vector3d(q.x, q.y, q.z)) + e.d) <= kAnnotationBand;
}

// Calls `visit` with each found entry, the map plane matching it best and the frame's pixel
// labels.
void forEachFoundEntry(const PlaneDetector& detector, const CloudView& view, const std::vector<Entry>& entries,
                       const std::vector<bool>& found,
                       const std::function<void(const Entry&, const DetectedPlane&, const std::vector<int>&)>& visit)
{
  std::vector<int> labels;
  detector.labelPixels(view, labels);
  for (size_t i = 0; i < entries.size(); ++i)
  {
    if (!found[i]) continue;
    const DetectedPlane* best = bestMatchingPlane(detector, entries[i]);
    if (best) visit(entries[i], *best, labels);
  }
}

// The pixels we label with each found entry's plane (the nodelet's ~inliers) against the points
// of the entry's face: see OsdInlierCoverage.
void inlierCoverage(const PlaneDetector& detector, const CloudView& view,
                    const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, const std::vector<Entry>& entries,
                    const std::vector<bool>& found, OsdResults& results)
{
  forEachFoundEntry(detector, view, entries, found, [&](const Entry& e, const DetectedPlane& best,
                                                        const std::vector<int>& labels) {
    OsdInlierCoverage coverage;
    coverage.table = e.object == 0;
    for (size_t p = 0; p < labels.size(); ++p)
    {
      const pcl::PointXYZRGBL& q = cloud.points[p];
      const bool ours = labels[p] == best.id && std::isfinite(q.z);
      const bool face = onEntryFace(q, e);
      coverage.face += face;
      coverage.ours += ours;
      coverage.both += ours && face;
      coverage.ours_on_plane +=
          ours && std::abs(e.normal.dot(Eigen::Vector3d(q.x, q.y, q.z)) + e.d) <= kAnnotationBand;
    }
    results.inlier_coverage.push_back(coverage);
  });
}

void fitErrors(const PlaneDetector& detector, const CloudView& view, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud,
               const std::string& frame, const std::vector<Entry>& entries, const std::vector<bool>& found,
               std::vector<OsdFitError>& out)
{
  constexpr int kMargin = 10;  // px: a face's labelled pixels may reach a little past its annotated box
  forEachFoundEntry(detector, view, entries, found, [&](const Entry& e, const DetectedPlane& best,
                                                        const std::vector<int>& labels) {
    int labelled = 0;
    std::vector<char> ours(labels.size(), 0);
    for (int v = 0; v < view.height; ++v)
      for (int u = 0; u < view.width; ++u)
      {
        const size_t i = static_cast<size_t>(v) * view.width + u;
        const bool inside = e.object == 0 || (u >= e.box[0] - kMargin && u <= e.box[2] + kMargin &&
                                              v >= e.box[1] - kMargin && v <= e.box[3] + kMargin);
        ours[i] = inside && std::isfinite(cloud.points[i].z) && labels[i] == best.id;
        labelled += ours[i];
      }
    OsdFitError fit{frame, e.name, e.points, labelled};
    matches(best.normal, best.d, e, &fit.angle);
    const FramePlane* fitted = nullptr;
    double fitted_angle = kMatchAngle;
    for (const FramePlane& p : detector.lastFramePlanes())
      if (unsignedAngle(p.normal, best.normal) <= fitted_angle &&
          std::abs((p.normal.dot(best.normal) >= 0.0 ? p.d : -p.d) - best.d) <= kMatchDistance)
      {
        fitted_angle = unsignedAngle(p.normal, best.normal);
        fitted = &p;
      }
    if (fitted && fitted->parallel && !fitted->own_normal.isZero())
    {
      fit.snapped = true;
      fit.own_angle = unsignedAngle(fitted->own_normal, e.normal);
      const Eigen::Vector3d n = fitted->own_normal.normalized();
      // The information's smallest eigenvalue across the normal: the loosest direction.
      const Eigen::Matrix3d across = (Eigen::Matrix3d::Identity() - n * n.transpose()) * fitted->own_normal_information *
                                     (Eigen::Matrix3d::Identity() - n * n.transpose());
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> info(across);
      fit.own_sigma = info.eigenvalues()(1) > 0.0 ? 1.0 / std::sqrt(info.eigenvalues()(1)) : 0.0;
    }
    Eigen::Vector3d labelled_normal;
    fit.labelled_fit_angle = maskedPlaneNormal(cloud, ours, 3, labelled_normal) ? unsignedAngle(labelled_normal, e.normal)
                                                                                 : M_PI / 2;
    out.push_back(fit);
  });
}

// Where the pixels of each of our duplicate planes lie: see OsdDuplicate.
void describeDuplicates(const PlaneDetector& detector, const CloudView& view,
                        const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, const std::string& frame,
                        const std::vector<Entry>& entries, const std::vector<int>& duplicate_of,
                        std::vector<OsdDuplicate>& out)
{
  std::vector<int> labels;
  for (size_t k = 0; k < duplicate_of.size(); ++k)
  {
    if (duplicate_of[k] < 0) continue;
    if (labels.empty()) detector.labelPixels(view, labels);
    const Entry& e = entries[duplicate_of[k]];
    const DetectedPlane& plane = detector.planes()[k];  // the detections are the map's planes in order
    OsdDuplicate duplicate;
    duplicate.frame = frame;
    duplicate.entry = e.name;
    matches(plane.normal, plane.d, e, nullptr, &duplicate.offset);
    double sum = 0.0, squares = 0.0;
    std::map<uint32_t, int> by_object;
    for (size_t i = 0; i < labels.size(); ++i)
    {
      const pcl::PointXYZRGBL& q = cloud.points[i];
      if (labels[i] != plane.id || !std::isfinite(q.z)) continue;
      const double distance = e.normal.dot(Eigen::Vector3d(q.x, q.y, q.z)) + e.d;
      sum += distance;
      squares += distance * distance;
      ++by_object[q.label / 10];
      ++duplicate.pixels;
    }
    if (duplicate.pixels > 0)
    {
      duplicate.mean_distance = sum / duplicate.pixels;
      duplicate.rms = std::sqrt(std::max(0.0, squares / duplicate.pixels - duplicate.mean_distance * duplicate.mean_distance));
      const auto most = std::max_element(by_object.begin(), by_object.end(),
                                         [](const auto& a, const auto& b) { return a.second < b.second; });
      duplicate.object = most->first == 0 ? "table" : "obj" + std::to_string(10 * most->first);
      duplicate.object_share = static_cast<double>(most->second) / duplicate.pixels;
    }
    out.push_back(duplicate);
  }
}

// The table's blocks (within 1 cm of its annotated plane, 32 points or more) against the
// detector's noise model: see OsdResults.
void tableNoise(const PlaneDetector& detector, const std::vector<Entry>& entries, OsdResults& results)
{
  const FrameData& frame = detector.lastFrame();
  for (const Entry& e : entries)
  {
    if (e.name != "table") continue;
    for (size_t b = 0; b < frame.blocks.size(); ++b)
    {
      const BlockInfo& info = frame.blocks[b];
      if (!info.valid || frame.points(static_cast<int>(b)) < 32) continue;
      const double offset = e.normal.dot(info.centroid) + e.d;
      if (std::abs(offset) > 0.01) continue;
      const double sigma = frame.noise.sigma(info.centroid.z());
      results.table_block_spread.push_back(e.normal.dot(info.covariance * e.normal) / (sigma * sigma));
      results.table_centroid_chi2.push_back(offset * offset / info.centroid_variance);
    }
  }
}

// The mask without its outer `radius` pixels: a pixel stays when the (2 radius + 1)^2 square
// around it lies in the mask (by prefix sums along rows, then columns).
std::vector<char> erodeMask(const std::vector<char>& mask, int width, int height, int radius)
{
  auto erodeAlong = [&](const std::vector<char>& in, bool rows) {
    std::vector<char> out(in.size(), 0);
    const int lines = rows ? height : width, length = rows ? width : height;
    std::vector<int> prefix(static_cast<size_t>(length) + 1);
    for (int l = 0; l < lines; ++l)
    {
      auto at = [&](int k) { return rows ? static_cast<size_t>(l) * width + k : static_cast<size_t>(k) * width + l; };
      for (int k = 0; k < length; ++k) prefix[k + 1] = prefix[k] + in[at(k)];
      for (int k = radius; k + radius < length; ++k)
        out[at(k)] = prefix[k + radius + 1] - prefix[k - radius] == 2 * radius + 1;
    }
    return out;
  };
  return erodeAlong(erodeAlong(mask, true), false);
}

// How much the annotation's normal owes to a face's outer pixels. An entry is the least-squares
// plane of its object's points within 6 mm (README); that band without its outer 8 px, which a
// detector working on 8 px blocks does not claim, is its interior. Where the band reproduces the
// entry (another face's fold in the band would not), the band is also fitted without its outer 4 px.
void rimSensitivity(const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, const std::vector<Entry>& entries,
                    const std::vector<bool>& found, const std::vector<double>& our_angles,
                    const std::vector<Eigen::Vector3d>& our_normals, OsdResults& results)
{
  constexpr double kReproduced = 0.005;  // rad: the band's own fit is the entry
  constexpr int kMinPixels = 100;        // for a face's fit after erosion
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  for (size_t i = 0; i < entries.size(); ++i)
  {
    const Entry& e = entries[i];
    if (!found[i]) continue;
    std::vector<char> band(cloud.points.size(), 0);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    int band_pixels = 0;
    for (size_t p = 0; p < cloud.points.size(); ++p)
    {
      const pcl::PointXYZRGBL& q = cloud.points[p];
      band[p] = onEntryFace(q, e);
      if (!band[p]) continue;
      centroid += Eigen::Vector3d(q.x, q.y, q.z);
      ++band_pixels;
    }
    Eigen::Vector3d whole, without4, without8;
    if (!maskedPlaneNormal(cloud, erodeMask(band, width, height, 8), kMinPixels, without8)) continue;
    if (without8.dot(e.normal) < 0.0) without8 = -without8;
    // The annotation's tilt from the interior, split along the face toward the camera (the ray to
    // the band's centroid, less its part along the normal) and across that.
    // Seen head-on the face has no such direction; its tilt then counts as across.
    const Eigen::Vector3d ray = centroid / band_pixels;
    const Eigen::Vector3d along = ray - without8 * without8.dot(ray);
    const Eigen::Vector3d toward_camera =
        along.norm() > 1e-9 ? Eigen::Vector3d(-along.normalized()) : Eigen::Vector3d(without8.unitOrthogonal());
    const Eigen::Vector3d tilt = e.normal - without8 * without8.dot(e.normal);
    results.interior_fits.push_back({unsignedAngle(our_normals[i], without8), unsignedAngle(e.normal, without8),
                                     tilt.dot(toward_camera), tilt.dot(without8.cross(toward_camera))});
    if (e.object == 0 || !maskedPlaneNormal(cloud, band, kMinPixels, whole) ||
        unsignedAngle(whole, e.normal) > kReproduced)
      continue;
    if (!maskedPlaneNormal(cloud, erodeMask(band, width, height, 4), kMinPixels, without4)) continue;
    results.rim_checks.push_back({our_angles[i], unsignedAngle(without4, e.normal), unsignedAngle(without8, e.normal)});
  }
}

// Each entry of a frame with a table, by kind, with our error on it (see OsdEntryAngle).
void entryAngles(const std::vector<Entry>& entries, const std::vector<bool>& found,
                 const std::vector<double>& our_angles, const std::vector<Eigen::Vector3d>& our_normals,
                 OsdResults& results)
{
  constexpr double kParallelToTable = 0.2;  // rad: the annotated tops lie within 0.08, the sides near pi/2
  constexpr double kSameNormal = 1e-6;      // rad: a snapped plane has the known normal to rounding
  const auto table = std::find_if(entries.begin(), entries.end(), [](const Entry& e) { return e.object == 0; });
  if (table == entries.end()) return;
  const size_t t = static_cast<size_t>(table - entries.begin());
  // Along the table toward the camera: the optical axis on the table's plane, reversed.
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d toward_camera = -(axis - table->normal * table->normal.dot(axis)).normalized();
  for (size_t i = 0; i < entries.size(); ++i)
  {
    OsdEntryAngle angle;
    angle.found = found[i];
    angle.ours = our_angles[i];
    angle.annotated_to_table = unsignedAngle(entries[i].normal, table->normal);
    if (i == t)
      angle.kind = OsdEntryAngle::Kind::kTable;
    else if (angle.annotated_to_table <= kParallelToTable)
      angle.kind = OsdEntryAngle::Kind::kParallelToTable;
    const double sign = entries[i].normal.dot(table->normal) >= 0.0 ? 1.0 : -1.0;
    angle.annotated_toward_camera = (sign * entries[i].normal - table->normal).dot(toward_camera);
    angle.ours_parallel_to_our_table =
        i != t && found[i] && found[t] && unsignedAngle(our_normals[i], our_normals[t]) <= kSameNormal;
    results.entry_angles.push_back(angle);
  }
}

// Where each object of a joined entry lies from its plane (see OsdJoinedEntry).
void joinedEntries(const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, const std::string& frame,
                   const std::vector<Entry>& entries, OsdResults& results)
{
  constexpr double kBin = 0.002;  // m
  const int bins = static_cast<int>(std::lround(2.0 * kMatchDistance / kBin));
  for (const Entry& e : entries)
  {
    std::set<int> objects;  // label / 10 of each "objNN" part of the name
    for (size_t at = e.name.find("obj"); at != std::string::npos; at = e.name.find("obj", at + 3))
      objects.insert(std::stoi(e.name.substr(at + 3, 2)) / 10);
    if (objects.size() < 2) continue;
    OsdJoinedEntry joined{frame, e.name, {}};
    for (int object : objects)
    {
      std::vector<int> histogram(static_cast<size_t>(bins), 0);
      for (int v = std::max(0, e.box[1]); v <= std::min(static_cast<int>(cloud.height) - 1, e.box[3]); ++v)
        for (int u = std::max(0, e.box[0]); u <= std::min(static_cast<int>(cloud.width) - 1, e.box[2]); ++u)
        {
          const pcl::PointXYZRGBL& q = cloud.at(u, v);
          if (q.label < 20 || static_cast<int>(q.label / 10) != object || !std::isfinite(q.z)) continue;
          const double distance = e.normal.dot(Eigen::Vector3d(q.x, q.y, q.z)) + e.d;
          const int bin = static_cast<int>(std::floor((distance + kMatchDistance) / kBin));
          if (bin >= 0 && bin < bins) ++histogram[static_cast<size_t>(bin)];
        }
      const auto mode = std::max_element(histogram.begin(), histogram.end());
      const double offset = *mode == 0 ? std::nan("")
                                       : (static_cast<double>(mode - histogram.begin()) + 0.5) * kBin - kMatchDistance;
      joined.parts.emplace_back("obj" + std::to_string(10 * object), offset);
    }
    results.joined_entries.push_back(joined);
  }
}

// Objects of a curved-object frame with no annotated face: cans and mugs.
std::set<uint32_t> curvedObjects(const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, const std::vector<Entry>& entries)
{
  std::set<uint32_t> objects;
  for (const auto& p : cloud.points)
    if (p.label >= 20) objects.insert(p.label / 10);
  for (const Entry& e : entries) objects.erase(static_cast<uint32_t>(e.object));
  return objects;
}

// Our detections whose labelled pixels lie mostly on one curved object.
int planesOnCurvedObjects(const PlaneDetector& detector, const CloudView& view,
                          const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, const std::set<uint32_t>& curved)
{
  if (curved.empty()) return 0;
  std::vector<int> labels;
  detector.labelPixels(view, labels);
  int count = 0;
  for (const DetectedPlane& plane : detector.planes())
  {
    std::map<uint32_t, int> by_object;
    int total = 0;
    for (size_t i = 0; i < labels.size(); ++i)
      if (labels[i] == plane.id)
      {
        ++total;
        ++by_object[cloud.points[i].label / 10];
      }
    for (uint32_t object : curved)
      if (total > 0 && by_object[object] * 2 > total) ++count;
  }
  return count;
}

}  // namespace

bool writeSegmentedPicture(const std::string& path, const PlaneDetector& detector, const CloudView& view, std::string* error)
{
  std::vector<int> labels;
  detector.labelPixels(view, labels);
  std::vector<uint8_t> rgb(view.size() * 3, 0);
  for (int v = 0; v < view.height; ++v)
    for (int u = 0; u < view.width; ++u)
    {
      const size_t i = static_cast<size_t>(v) * view.width + u;
      float x, y, z;
      view.point(u, v, x, y, z);
      if (!std::isfinite(z)) continue;
      uint8_t c[3] = {90, 90, 90};
      if (labels[i] >= 0)
      {
        // Saturated hues a golden angle apart, so no plane looks like the grey of "no plane".
        const double hue = std::fmod(labels[i] * 0.618033988749895, 1.0) * 6.0;
        const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
        const double rgb_hue[6][3] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
        const double* f = rgb_hue[static_cast<int>(hue) % 6];
        for (int k = 0; k < 3; ++k) c[k] = static_cast<uint8_t>(60 + 195 * f[k]);
      }
      std::copy(c, c + 3, rgb.begin() + 3 * i);
    }
  return writePng(path, view.width, view.height, rgb, error);
}

bool evaluateOsdLearn(const std::string& dir, const DetectorParams& params, bool with_pcl, bool with_fit_errors,
                      const std::string& picture_dir, OsdResults& results, std::string* error)
{
  nlohmann::json annotations;
  try
  {
    std::ifstream in(dir + "/annotations.json");
    if (!in)
    {
      if (error) *error = dir + "/annotations.json cannot be read";
      return false;
    }
    in >> annotations;
  }
  catch (const std::exception& e)
  {
    if (error) *error = dir + "/annotations.json: " + e.what();
    return false;
  }
  results = OsdResults();
  OsdMethodResult single, copies, ransac, organized;
  single.method = "Hough 1024, one frame";
  copies.method = "Hough 1024, five copies";
  ransac.method = "PCL RANSAC (1 cm)";
  organized.method = "PCL OMPS";
  single.curved_planes = 0;
  const std::set<std::string> picture_frames = {"learn0.pcd", "learn20.pcd", "learn28.pcd", "learn36.pcd", "learn40.pcd"};
  for (int index = 0;; ++index)
  {
    const std::string name = "learn" + std::to_string(index) + ".pcd";
    if (!annotations.contains(name)) break;
    std::vector<Entry> entries;
    for (const auto& e : annotations[name])
    {
      Entry entry{e["name"].get<std::string>(),
                  Eigen::Vector3d(e["normal"][0].get<double>(), e["normal"][1].get<double>(), e["normal"][2].get<double>()),
                  e["d"].get<double>(), e["points"].get<int>(), 0, {0, 0, -1, -1}};
      if (e.contains("bbox"))
        for (int k = 0; k < 4; ++k) entry.box[k] = e["bbox"][k].get<int>();
      if (entry.name.rfind("obj", 0) == 0) entry.object = std::stoi(entry.name.substr(3, 2)) / 10;
      entries.push_back(entry);
    }
    pcl::PointCloud<pcl::PointXYZRGBL> cloud;
    if (pcl::io::loadPCDFile(dir + "/" + name, cloud) != 0 || cloud.height < 2)
    {
      if (error) *error = dir + "/" + name + " cannot be read as an organized cloud";
      return false;
    }
    CloudView view;
    view.data = reinterpret_cast<const uint8_t*>(cloud.points.data());
    view.width = static_cast<int>(cloud.width);
    view.height = static_cast<int>(cloud.height);
    view.point_step = sizeof(pcl::PointXYZRGBL);
    view.row_step = view.point_step * cloud.width;

    PlaneDetector detector(params);
    std::vector<bool> found;
    for (int copy = 0; copy < kCopies; ++copy)
    {
      if (!detector.processFrame(view, Eigen::Isometry3d::Identity(), 0.1 * copy, error)) return false;
      if (copy > 0) continue;
      single.ms.push_back(detector.lastTimings().total_ms);
      std::vector<double> our_angles;
      std::vector<int> duplicate_of;
      std::vector<Eigen::Vector3d> our_normals;
      score(entries, mapPlanes(detector), single, &found, &our_angles, &duplicate_of, &our_normals);
      describeDuplicates(detector, view, cloud, name, entries, duplicate_of, results.duplicates);
      for (size_t i = 0; i < entries.size(); ++i)
        if (!found[i])
        {
          OsdMiss miss;
          miss.frame = name;
          miss.entry = entries[i].name;
          miss.points = entries[i].points;
          miss.reason = missReason(detector, entries[i], &miss.nearest_offsets);
          ++results.misses_by_reason[miss.reason];
          results.misses.push_back(miss);
        }
      if (with_fit_errors) fitErrors(detector, view, cloud, name, entries, found, results.fit_errors);
      tableNoise(detector, entries, results);
      rimSensitivity(cloud, entries, found, our_angles, our_normals, results);
      entryAngles(entries, found, our_angles, our_normals, results);
      inlierCoverage(detector, view, cloud, entries, found, results);
      joinedEntries(cloud, name, entries, results);
      if (index >= kFirstCurvedFrame)
        single.curved_planes += planesOnCurvedObjects(detector, view, cloud, curvedObjects(cloud, entries));
      if (!picture_dir.empty() && picture_frames.count(name))
      {
        const std::string path = picture_dir + "/osd_" + name.substr(0, name.size() - 4) + ".png";
        std::string png_error;
        if (writeSegmentedPicture(path, detector, view, &png_error))
          results.pictures.push_back(path);
        else
          std::fprintf(stderr, "%s\n", png_error.c_str());
      }
    }
    copies.ms.push_back(detector.lastTimings().total_ms);
    score(entries, mapPlanes(detector), copies);
    if (!with_pcl) continue;
    const auto pcl_cloud = toPclCloud(view);
    auto t = Clock::now();
    const auto r = pclRansacPlanes(pcl_cloud, 1000, 0.01, kPclMinInliers);
    ransac.ms.push_back(msSince(t));
    score(entries, r, ransac);
    t = Clock::now();
    const auto o = pclOrganizedPlanes(pcl_cloud, kPclMinInliers);
    organized.ms.push_back(msSince(t));
    score(entries, o, organized);
  }
  if (single.frames == 0)
  {
    if (error) *error = dir + "/annotations.json names no learnN.pcd frame";
    return false;
  }
  results.methods = {single, copies};
  if (with_pcl) results.methods.insert(results.methods.end(), {ransac, organized});
  return true;
}

const FirstSight* nearestFirstSight(const PlaneDetector& detector,
                                    const std::function<double(const Eigen::Vector3d& normal, double d)>& cost)
{
  const std::vector<FramePlane>& measured = detector.lastFramePlanes();
  const std::vector<FirstSight>& first_sights = detector.map().lastFirstSights();
  const FirstSight* nearest = nullptr;
  double nearest_cost = 0.0;
  for (size_t i = 0; i < measured.size() && i < first_sights.size(); ++i)
  {
    const double c = cost(measured[i].normal, measured[i].d);
    if (c >= 0.0 && (!nearest || c < nearest_cost))
    {
      nearest = &first_sights[i];
      nearest_cost = c;
    }
  }
  return nearest;
}

std::string osdLearnMarkdown(const OsdResults& results, const std::string& picture_prefix)
{
  char line[512];
  std::string md =
      "| method | found | duplicates / frame | unmatched / frame | planes on cans and mugs | E_angle (rad) | E_d (m) | "
      "median ms |\n|---|---|---|---|---|---|---|---|\n";
  for (const OsdMethodResult& m : results.methods)
  {
    std::snprintf(line, sizeof(line), "| %s | %.1f %% (%d/%d) | %.2f | %.2f | %s | %.4f +- %.4f | %.4f +- %.4f | %.1f |\n",
                  m.method.c_str(), m.foundPercent(), m.found, m.entries, static_cast<double>(m.duplicates) / m.frames,
                  static_cast<double>(m.unmatched) / m.frames,
                  m.curved_planes < 0 ? "-" : std::to_string(m.curved_planes).c_str(), mean(m.angle_errors),
                  standardDeviation(m.angle_errors), mean(m.d_errors), standardDeviation(m.d_errors), median(m.ms));
    md += line;
  }
  if (!results.rim_checks.empty()) md += "\n" + osdRimMarkdown(results);
  if (!results.interior_fits.empty()) md += "\n" + osdInteriorMarkdown(results);
  if (!results.inlier_coverage.empty()) md += "\n" + osdInlierMarkdown(results);
  if (!results.entry_angles.empty()) md += "\n" + osdParallelFacesMarkdown(results);
  if (!results.joined_entries.empty()) md += "\n" + osdJoinedEntriesMarkdown(results);
  if (!results.duplicates.empty())
  {
    md += "\nOur duplicates (one frame): each plane of ours matching an entry an earlier one matches, and where "
          "the pixels it labels lie (distance from the entry's plane, + toward the camera):";
    for (const OsdDuplicate& d : results.duplicates)
    {
      std::snprintf(line, sizeof(line), " %s %s, %.1f mm off it, %d pixels at %+.1f mm (RMS %.1f mm), %.0f %% on %s;",
                    d.frame.c_str(), d.entry.c_str(), 1000.0 * d.offset, d.pixels, 1000.0 * d.mean_distance,
                    1000.0 * d.rms, 100.0 * d.object_share, d.object.c_str());
      md += line;
    }
    md += "\n";
  }
  md += "\nOur misses (one frame), by what became of the nearest candidate:";
  for (const auto& [reason, count] : results.misses_by_reason) md += " " + reason + ": " + std::to_string(count) + ";";
  md += "\n\n| frame | entry | points | why | nearest candidate off by |\n|---|---|---|---|---|\n";
  for (const OsdMiss& miss : results.misses)
  {
    std::snprintf(line, sizeof(line), "| %s | %s | %d | %s | %s |\n", miss.frame.c_str(), miss.entry.c_str(),
                  miss.points, miss.reason.c_str(), miss.nearest_offsets.empty() ? "-" : miss.nearest_offsets.c_str());
    md += line;
  }
  md += "\n";
  for (const std::string& path : results.pictures)
  {
    const std::string file = path.substr(path.find_last_of('/') + 1);
    md += "![" + file + "](" + picture_prefix + file + ") ";
  }
  md += "\n\n";
  return md;
}

std::string osdRimMarkdown(const OsdResults& results)
{
  std::vector<double> ours, without4, without8;
  for (const OsdRimCheck& c : results.rim_checks)
  {
    ours.push_back(c.ours);
    without4.push_back(c.without_4px);
    without8.push_back(c.without_8px);
  }
  char line[640];
  std::snprintf(line, sizeof(line),
                "How much the annotated normals owe to the faces' outer pixels: on the %zu found faces whose annotation "
                "is reproduced (within 0.005 rad) by the least-squares plane of its object's points within 6 mm, that "
                "band fitted again without its outer 4 px lies %.4f rad (mean) off the annotation, without its outer "
                "8 px %.4f rad; ours on the same faces %.4f rad.\n",
                results.rim_checks.size(), mean(without4), mean(without8), mean(ours));
  return line;
}

std::string osdInteriorMarkdown(const OsdResults& results)
{
  std::vector<double> ours, annotation, toward, across;
  int toward_count = 0;
  for (const OsdInteriorFit& f : results.interior_fits)
  {
    ours.push_back(f.ours);
    annotation.push_back(f.annotation);
    toward.push_back(f.annotation_toward_camera);
    across.push_back(f.annotation_across);
    toward_count += f.annotation_toward_camera > 0.0;
  }
  char line[768];
  std::snprintf(line, sizeof(line),
                "Against the faces' interiors (each found entry's 6 mm band of its object's points without its outer "
                "8 px, fitted again; %zu entries, tables included): ours E_angle %.4f rad, the annotation %.4f rad. "
                "The annotation tilts from the interior toward the camera by %+.4f rad (mean; %d of %zu toward it) "
                "and across that by %+.4f rad: a face's outer pixels lean its fit toward the sensor.\n",
                results.interior_fits.size(), mean(ours), mean(annotation), mean(toward), toward_count,
                results.interior_fits.size(), mean(across));
  return line;
}

std::string osdInlierMarkdown(const OsdResults& results)
{
  long face[2] = {0, 0}, ours[2] = {0, 0}, both[2] = {0, 0}, on_plane[2] = {0, 0};
  size_t entries[2] = {0, 0};
  for (const OsdInlierCoverage& c : results.inlier_coverage)
  {
    const int k = c.table ? 0 : 1;
    face[k] += c.face;
    ours[k] += c.ours;
    both[k] += c.both;
    on_plane[k] += c.ours_on_plane;
    ++entries[k];
  }
  auto share = [](long part, long whole) { return whole > 0 ? 100.0 * part / whole : 0.0; };
  char line[640];
  std::snprintf(line, sizeof(line),
                "Inliers (the pixels we label with a found entry's plane, as ~inliers publishes them) against the "
                "entry's face (its object's points within 6 mm of its plane), pooled: tables (%zu) %.1f %% of the "
                "face's points labelled, %.1f %% of ours on the face and %.1f %% within 6 mm of its plane; faces "
                "(%zu) %.1f %%, %.1f %% and %.1f %%.\n",
                entries[0], share(both[0], face[0]), share(both[0], ours[0]), share(on_plane[0], ours[0]), entries[1],
                share(both[1], face[1]), share(both[1], ours[1]), share(on_plane[1], ours[1]));
  return line;
}

std::string osdParallelFacesMarkdown(const OsdResults& results)
{
  using Kind = OsdEntryAngle::Kind;
  std::vector<double> tables, parallel, snapped, unsnapped, others, annotated_to_table, toward;
  int parallel_entries = 0, leaning_toward = 0;
  for (const OsdEntryAngle& a : results.entry_angles)
  {
    if (a.kind == Kind::kParallelToTable)
    {
      ++parallel_entries;
      annotated_to_table.push_back(a.annotated_to_table);
      toward.push_back(a.annotated_toward_camera);
      leaning_toward += a.annotated_toward_camera > 0.0;
    }
    if (!a.found) continue;
    if (a.kind == Kind::kTable)
      tables.push_back(a.ours);
    else if (a.kind == Kind::kOther)
      others.push_back(a.ours);
    else
    {
      parallel.push_back(a.ours);
      (a.ours_parallel_to_our_table ? snapped : unsnapped).push_back(a.ours);
    }
  }
  char line[1024];
  std::snprintf(line, sizeof(line),
                "E_angle by surface (one frame): tables %.4f rad (%zu found); faces parallel to their table (within "
                "0.2 rad of its annotated normal: box tops) %.4f rad (%zu found of %d), of which %zu with our table "
                "plane's normal (snapped to it) %.4f rad and the other %zu %.4f rad; other faces %.4f rad (%zu found). "
                "The parallel faces' annotated normals lie %.4f rad (mean) off their table's, %d of %d leaning toward "
                "the camera (%+.4f rad mean along the table): resting on the table they are parallel to it, so a "
                "one-sided tilt is most likely the sensor's; a fit of each face's own points (the annotation's) keeps "
                "it, a snap to the table's direction removes it.\n",
                mean(tables), tables.size(), mean(parallel), parallel.size(), parallel_entries, snapped.size(),
                mean(snapped), unsnapped.size(), mean(unsnapped), mean(others), others.size(), mean(annotated_to_table),
                leaning_toward, parallel_entries, mean(toward));
  return line;
}

std::string osdJoinedEntriesMarkdown(const OsdResults& results)
{
  std::string md =
      "Entries joining faces of several objects, and where each object's points nearest the entry's plane lie "
      "(mode of 2 mm bins within 3 cm, in its box; + toward the camera):";
  int apart = 0;
  char part[96];
  for (const OsdJoinedEntry& joined : results.joined_entries)
  {
    md += " " + joined.frame + " " + joined.entry + ":";
    for (const auto& [object, offset] : joined.parts)
    {
      if (std::isnan(offset))
        std::snprintf(part, sizeof(part), " %s none,", object.c_str());
      else
        std::snprintf(part, sizeof(part), " %s %+.0f mm,", object.c_str(), 1000.0 * offset);
      md += part;
      apart += std::isfinite(offset) && std::abs(offset) > kAnnotationBand;
    }
    md.back() = ';';
  }
  if (apart == 0)
    return md + " every part lies within the annotation's 6 mm band of its entry's plane.\n";
  return md + " " + std::to_string(apart) +
         " part(s) lie more than the annotation's 6 mm band off their entry's plane: each a surface of its own that "
         "the entry matches within 3 cm, so a detector that keeps it apart from the entry's plane reports a "
         "duplicate of the entry.\n";
}

std::string osdNoiseMarkdown(const OsdResults& results)
{
  char line[320];
  std::snprintf(line, sizeof(line),
                "Noise on the table's %zu blocks against the model: spread along the normal / sigma^2 median %.3f "
                "(1 as modelled); centroid offset^2 / centroid variance median %.3f (0.455 as modelled)\n",
                results.table_block_spread.size(), median(results.table_block_spread),
                median(results.table_centroid_chi2));
  return line;
}

std::string osdFitErrorsMarkdown(const OsdResults& results)
{
  std::vector<OsdFitError> sorted = results.fit_errors;
  std::sort(sorted.begin(), sorted.end(), [](const OsdFitError& a, const OsdFitError& b) { return a.angle > b.angle; });
  std::string md = "| frame | entry | points | E_angle ours (rad) | E_angle of the LSQ plane of our labelled pixels | "
                   "those pixels | snapped: E_angle of its own normal, that normal's sigma |\n|---|---|---|---|---|---|---|\n";
  char line[256];
  for (const OsdFitError& f : sorted)
  {
    char own[32] = "-";  // the matching plane labels no pixel near the face
    if (f.labelled >= 3) std::snprintf(own, sizeof(own), "%.4f", f.labelled_fit_angle);
    char snap[48] = "-";
    if (f.snapped) std::snprintf(snap, sizeof(snap), "%.4f, %.4f", f.own_angle, f.own_sigma);
    std::snprintf(line, sizeof(line), "| %s | %s | %d | %.4f | %s | %d | %s |\n", f.frame.c_str(), f.entry.c_str(),
                  f.points, f.angle, own, f.labelled, snap);
    md += line;
  }
  return md;
}

}  // namespace hough_plane_detector
