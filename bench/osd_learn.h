// Real frames with annotated planes (../shared/data/osd-learn, its README gives the protocol):
// each frame alone, and five copies of it (a still camera), through our detector, and once
// through PCL's RANSAC loop and organized multi-plane segmentation; scored against
// annotations.json (a detection matches an entry within 0.06 rad and 3 cm).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "hough_plane_detector/core/cloud_view.h"
#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/plane_detector.h"

namespace hough_plane_detector
{

// How the last frame's plane nearest a target voted at first sight (PlaneMap::lastFirstSights):
// of the frame's planes that `cost` scores (>= 0; negative: not within the match tolerance),
// the one of least cost; nullptr when there is none.
const FirstSight* nearestFirstSight(const PlaneDetector& detector,
                                    const std::function<double(const Eigen::Vector3d& normal, double d)>& cost);

struct OsdMethodResult
{
  std::string method;
  int entries = 0;         // annotated planes
  int found = 0;           // entries some detection matched
  int duplicates = 0;      // detections beyond the first that matched an already matched entry
  int detections = 0;
  int unmatched = 0;       // detections that match no entry (not necessarily false: see the README)
  int curved_planes = -1;  // learn33-44: detections whose support lies mostly on one curved object (-1: not measured)
  int frames = 0;
  std::vector<double> angle_errors, d_errors, ms;
  double foundPercent() const { return entries ? 100.0 * found / entries : 0.0; }
};

struct OsdMiss
{
  std::string frame, entry;
  int points = 0;
  std::string reason;  // what became of its candidate in our detector
  std::string nearest_offsets;  // that candidate's angle and offset from the entry ("" when none)
};

// A plane of ours counted as a duplicate (one frame: it matches an entry an earlier plane of
// ours matches), and where the pixels we label with it lie: a surface of its own that is not
// annotated (under 2000 points, within 3 cm of an entry) shows as such.
struct OsdDuplicate
{
  std::string frame, entry;
  double offset = 0.0;         // our plane's offset from the entry's (m)
  int pixels = 0;              // its labelled pixels with a return
  double mean_distance = 0.0;  // their signed distance from the entry's plane (m, + toward the camera)
  double rms = 0.0;            // about that mean (m)
  std::string object;          // the label under most of them: table, obj20, obj30, ...
  double object_share = 0.0;
};

// A found entry's normal error (one frame), beside that of the least-squares plane of the
// pixels our detector labels with the matching plane (inside the entry's box, 10 px margin):
// a large first with a small second means the plane's points were right and its normal was
// not (a known normal taken, a part of the face fitted).
struct OsdFitError
{
  std::string frame, entry;
  int points = 0;
  int labelled = 0;                // our labelled pixels the second fit used
  double angle = 0.0;              // ours against the annotation (rad)
  double labelled_fit_angle = 0.0;  // least squares of our labelled pixels against the annotation
  // This frame's fit of the face (the frame plane nearest the map plane): snapped to a known
  // normal, and then the error of the normal its own blocks fit and that normal's sigma.
  bool snapped = false;
  double own_angle = 0.0, own_sigma = 0.0;
};

// A found face's normal error, ours and that of the annotation's own 6 mm band without its
// outer 4 or 8 px, all against the annotation (rad): see osdRimMarkdown.
struct OsdRimCheck
{
  double ours = 0.0;
  double without_4px = 0.0;
  double without_8px = 0.0;
};

// A found entry against its interior (its 6 mm band without the outer 8 px, fitted again): our
// normal's angle to it, the annotation's, and the annotation's signed tilt from it along the face
// toward the camera and across that (rad): see osdInteriorMarkdown.
struct OsdInteriorFit
{
  double ours = 0.0;
  double annotation = 0.0;
  double annotation_toward_camera = 0.0;
  double annotation_across = 0.0;
};

// An annotated entry of a frame with a table, for E_angle by kind of surface. A face within
// 0.2 rad of the table's annotated normal rests parallel to it in the world (a box top), so the
// angle between their annotated normals is most likely the sensor's error: a fit of the face's
// own points (the annotation's, a detector's unsnapped plane) keeps it, a snap to the table's
// direction does not.
struct OsdEntryAngle
{
  enum class Kind { kTable, kParallelToTable, kOther };
  Kind kind = Kind::kOther;
  bool found = false;
  double ours = 0.0;                  // our E_angle (rad), when found
  bool ours_parallel_to_our_table = false;  // our plane has our table plane's normal (snapped to it)
  double annotated_to_table = 0.0;    // angle between the entry's and the table's annotated normals (rad)
  double annotated_toward_camera = 0.0;  // the entry's normal less the table's, along the table toward the camera
};

// An entry the annotation joined from faces of several objects (README: faces of one infinite
// plane), and where each object's points nearest its plane lie: the mode of their distance (2 mm
// bins, within the 3 cm match, in the entry's box; + toward the camera). A part further off than
// the annotation's 6 mm band is a surface of its own that the entry still matches.
struct OsdJoinedEntry
{
  std::string frame, entry;
  std::vector<std::pair<std::string, double>> parts;  // object (obj20, ...), offset (m; NaN: no points)
};

// A found entry's inliers: the pixels we label with its matching plane against its face (its
// object's points within the annotation's 6 mm of its plane).
struct OsdInlierCoverage
{
  bool table = false;
  long face = 0;           // the face's points
  long ours = 0;           // our labelled pixels (with a return)
  long both = 0;           // ours on the face
  long ours_on_plane = 0;  // ours within 6 mm of the entry's plane, on whatever object
};

struct OsdResults
{
  std::vector<OsdMethodResult> methods;  // ours single frame, ours five copies, PCL RANSAC, PCL OMPS
  std::vector<OsdMiss> misses;           // ours, single frame
  std::vector<OsdDuplicate> duplicates;  // ours, single frame
  std::map<std::string, int> misses_by_reason;
  std::vector<OsdFitError> fit_errors;   // ours, single frame, every found entry (when asked for)
  std::vector<std::string> pictures;     // segmented frames written (PNG paths)
  // The sensor's noise against the model, on the blocks within 1 cm of each frame's annotated
  // table plane: a block's spread along the table's normal over the model's sigma^2 (1 for noise
  // as modelled, independent per pixel), and its centroid's squared offset from the plane over
  // the model's centroid variance (median 0.455, chi^2 with 1 dof, for errors as modelled).
  std::vector<double> table_block_spread, table_centroid_chi2;
  std::vector<OsdRimCheck> rim_checks;  // ours, single frame
  std::vector<OsdInteriorFit> interior_fits;  // ours, single frame, every found entry with an interior
  std::vector<OsdInlierCoverage> inlier_coverage;  // ours, single frame, every found entry
  std::vector<OsdEntryAngle> entry_angles;    // ours, single frame, every entry of a frame with a table
  std::vector<OsdJoinedEntry> joined_entries;  // the annotation's entries over several objects
};

// How far the annotation's normal moves without the faces' outer pixels, beside ours, as one
// markdown line: the scale below which E_angle cannot tell methods apart on these frames.
std::string osdRimMarkdown(const OsdResults& results);
// Ours and the annotation against the found entries' interiors, and the annotation's lean toward
// the camera, as one markdown line: whether E_angle measures us or the annotation's outlines.
std::string osdInteriorMarkdown(const OsdResults& results);
// The inliers' share of the faces' points and the share of them on the faces, for tables and
// for the other faces, as one markdown line.
std::string osdInlierMarkdown(const OsdResults& results);
// E_angle by kind of surface (tables, faces parallel to their table, other faces), with the
// annotated angle of the parallel faces to their table, as one markdown line: how much of E_angle
// is the sensor's tilt between surfaces the scene holds parallel.
std::string osdParallelFacesMarkdown(const OsdResults& results);
// The joined entries and their parts' offsets, as one markdown line.
std::string osdJoinedEntriesMarkdown(const OsdResults& results);
// The median of each of results' noise samples, as one markdown line.
std::string osdNoiseMarkdown(const OsdResults& results);

// The last frame of `detector` as a PNG, each pixel in its plane's colour (grey: on no plane,
// black: no return); `view` must be that frame.
bool writeSegmentedPicture(const std::string& path, const PlaneDetector& detector, const CloudView& view,
                           std::string* error);

// Runs the data set in `dir` (annotations.json beside learn*.pcd). `with_pcl` adds the two PCL
// methods, `with_fit_errors` fills results.fit_errors; `picture_dir`, when not empty, receives
// a few segmented frames as PNG. Returns false with `error` set when the data cannot be read.
bool evaluateOsdLearn(const std::string& dir, const DetectorParams& params, bool with_pcl, bool with_fit_errors,
                      const std::string& picture_dir, OsdResults& results, std::string* error);

// The Markdown section of RESULTS.md for these results.
std::string osdLearnMarkdown(const OsdResults& results, const std::string& picture_prefix);
// A Markdown table of results.fit_errors, largest error first.
std::string osdFitErrorsMarkdown(const OsdResults& results);

}  // namespace hough_plane_detector
