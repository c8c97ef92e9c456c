// Per-frame planes as connected regions of the normal estimator's pixel blocks, grown from
// seeds (Hough peaks first). A block joins a region when it is flat within the sensor's
// noise, its own normal agrees within its uncertainty and its centroid lies on the region's
// plane within its noise: every test is against the noise expected at the block's depth, so
// small near faces and large far walls are judged alike.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "hough_plane_detector/core/detector_params.h"
#include "hough_plane_detector/core/normal_estimator.h"

namespace hough_plane_detector
{

// A surface bending more than this (1/m: radius 0.5 m) is not a plane; cardboard faces and
// warped walls bend far less, pillars, balls and cans more...
constexpr double kMaxPlaneCurvature = 2.0;
// ...unless the bend moves no point of the region farther than this (m) from its plane: finer
// than a depth sensor resolves (a Kinect's disparity step is 0.7 mm at 0.5 m), as a box lid
// doming 1 mm over 5 cm at 0.7 m (curvature 3/m). A can of 3.3 cm radius passes only as a
// strip under 1.6 cm wide.
constexpr double kMaxPlaneSag = 0.001;
// How far a real face may depart from its plane: cardboard faces bow, panels warp (osd-learn's
// box faces by 2-5 mm over 15 cm, one face grown as two regions 5 mm apart).
constexpr double kSurfaceWarp = 0.005;
// A region ends where its surface does (endsWhereItsSurfaceDoes) when under this share of what
// lies around it continues it: most of its rim is creases, depth jumps or no returns. osd-learn's
// box tops seen over their front have 0.23-0.36 of their rim continuing; a cylinder's facet between
// its silhouettes continues along its axis, 0.48 in AFacetOfABallOrPillarUnderCorrelatedNoiseIsNoPlane.
constexpr double kMaxContinuingShareOfAFace = 0.4;
// Neighbouring surfaces meeting at more than this (rad, 29 deg) are two faces (a box's edge,
// a wall's corner, an open door); a gentler turn between a region and the blocks around it
// may be one surface curving on (a ball, a pillar) and is tested as such (continuesAndBends).
constexpr double kCreaseAngle = 0.5;

// One block of the last frame, camera frame, with the noise limits the tests use.
struct BlockInfo
{
  bool valid = false;       // at least 3 points
  bool planar = false;      // its spread along its normal is the sensor's noise, not an edge
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d ray = Eigen::Vector3d::UnitZ();  // unit direction from the sensor to the centroid
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // of its own points, toward the sensor
  double normal_tolerance = 0;   // largest angle to a region's normal its noise explains (rad)
  double normal_tolerance_cosine = 1;  // its cosine, tested for every block a region meets
  double centroid_variance = 0;  // expected scatter of the centroid about its true plane
  double tight_residual = 0;     // farthest a centroid may lie from a fitted plane
  double region_residual = 0;    // farthest it may lie from its region's plane: noise and systematic error
  double thickness_limit = 0;    // largest spread along the plane normal
  double fit_weight = 1;         // inverse depth-noise variance
  double random_depth_variance = 0;  // one point's random depth noise, quantization apart (0: no noise model)
  double quantization_step = 0;      // the sensor's depth step there (0: none)
  PointMoments weighted_centroid;  // its points moved to their centroid, weighted by fit_weight
};

constexpr double kFaceRoughness = 0.001;  // no face is flatter within a block (paint, cardboard), m

// The mean chi^2 per block that n block centroids exceed about their true plane with p = 0.01
// (chi^2 with n dof over n, its normal approximation).
inline double noiseBoundOfMeanChi2(size_t blocks)
{
  return 1.0 + 2.33 * std::sqrt(2.0 / static_cast<double>(std::max<size_t>(1, blocks)));
}

// True when the block's points scatter along n_cam no more than their depth noise can (moved
// along the rays: the random part within its p = 0.01 bound, quantization within half a step):
// a block across an edge or a step is thicker, and so is one whose rows straddle the image line
// of a plane through the sensor. Never beyond its thickness_limit; without a noise model (or
// under 2 points to judge) that limit alone.
bool blockThinAlong(const BlockInfo& info, double points, const Eigen::Vector3d& n_cam);

// Fills `info` (row-major over the estimator's block grid) from the estimator's last frame,
// its rows of blocks shared out over `team` (each block is described on its own).
void describeBlocks(const NormalEstimator& grid, const DetectorParams& params, const DepthNoiseModel& noise,
                    std::vector<BlockInfo>& info, ThreadTeam& team = ThreadTeam::callingThreadOnly());
// One row of blocks of that work, into `info` already sized to the grid.
void describeBlockRow(const NormalEstimator& grid, const DetectorParams& params, const DepthNoiseModel& noise, int by,
                      std::vector<BlockInfo>& info);

// Calls visit(neighbour) for each 4-neighbour of block b inside a bx_count x by_count grid.
template <class Visit>
void forEachNeighbour(int b, int bx_count, int by_count, Visit&& visit)
{
  const int bx = b % bx_count, by = b / bx_count;
  if (bx > 0) visit(b - 1);
  if (bx + 1 < bx_count) visit(b + 1);
  if (by > 0) visit(b - bx_count);
  if (by + 1 < by_count) visit(b + bx_count);
}

// A set of a block grid's blocks that empties in constant time: each block keeps the number of
// the set it was last put in. Before that number would overflow (after 2^31 sets, weeks at
// 30 Hz for a detector's long-lived scratch) the marks are cleared and it starts over.
class BlockMarks
{
public:
  // Empties the set, for a grid of `size` blocks.
  void clear(size_t size)
  {
    marks_.resize(size, 0);
    if (generation_ == std::numeric_limits<int>::max())
    {
      std::fill(marks_.begin(), marks_.end(), 0);
      generation_ = 0;
    }
    ++generation_;
  }
  bool contains(int b) const { return marks_[b] == generation_; }
  void insert(int b) { marks_[b] = generation_; }
  // Puts b in; false when it was in already.
  bool insertNew(int b)
  {
    if (marks_[b] == generation_) return false;
    marks_[b] = generation_;
    return true;
  }

private:
  std::vector<int> marks_;
  int generation_ = 0;
};

// The 4-connected components of a set of a block grid's blocks. Its marks are kept across
// calls, so that finding the components costs the set's size, not the grid's.
class BlockComponents
{
public:
  // Calls visit(component) for each component of `blocks` (distinct blocks of a bx_count x
  // by_count grid), in the order of their first block in `blocks`; `component` lives only
  // during the call, and `visit` must not call forEach of the same object.
  template <class Visit>
  void forEach(const std::vector<int>& blocks, int bx_count, int by_count, Visit&& visit)
  {
    const size_t size = static_cast<size_t>(bx_count) * by_count;
    members_.clear(size);
    reached_.clear(size);
    for (int b : blocks) members_.insert(b);
    for (int seed : blocks)
    {
      if (!reached_.insertNew(seed)) continue;
      component_.assign(1, seed);
      for (size_t head = 0; head < component_.size(); ++head)
        forEachNeighbour(component_[head], bx_count, by_count, [&](int nb) {
          if (members_.contains(nb) && reached_.insertNew(nb)) component_.push_back(nb);
        });
      visit(static_cast<const std::vector<int>&>(component_));
    }
  }

private:
  BlockMarks members_, reached_;
  std::vector<int> component_;
};

// Blocks on a region's rim may straddle the fold to a neighbouring surface (a stair's nosing,
// a shelf board's back edge against the wall); its interior, the blocks whose four neighbours
// are in it too, cannot. Fits use the interior when it has at least this many blocks.
constexpr size_t kMinInteriorBlocks = 6;
std::vector<int> interiorBlocks(const std::vector<int>& blocks, int bx_count, int by_count);

// A block's points all moved to their centroid: fits over many blocks then see the surface
// without the depth noise inside blocks, which would tilt their normals toward the rays.
PointMoments centroidMoments(const PointMoments& block);

// Centroid moments of the blocks, each weighted by the inverse variance of the sensor at its
// depth (BlockInfo::weighted_centroid): far points of a Kinect are an order of magnitude
// noisier, the precise ones decide.
PointMoments weightedCentroidMoments(const std::vector<BlockInfo>& info, const std::vector<int>& blocks);

struct PlaneRegion
{
  std::vector<int> blocks;
  std::vector<int> trimmed;  // joined while growing, beyond two sigmas of the final plane
  double points = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // camera frame, weighted fit of the centroids
  double d = 0;
};

class BlockRegionGrower
{
public:
  BlockRegionGrower(const NormalEstimator& grid, const std::vector<BlockInfo>& info, const DetectorParams& params);

  // Planar blocks not yet taken that agree with the camera-frame plane (normal, d), as
  // 4-connected components, largest first.
  std::vector<std::vector<int>> seedComponents(const Eigen::Vector3d& normal, double d, const std::vector<char>& taken);
  // Grows `seed` (with a first plane guess) over neighbouring blocks not taken, refitting the
  // plane after each sweep, until nothing more joins; then trims blocks beyond two sigmas of
  // the interior's plane (into `trimmed`) and fits the plane to what is left.
  PlaneRegion grow(const std::vector<int>& seed, const Eigen::Vector3d& normal, double d, const std::vector<char>& taken);
  // True when the block may join a region of plane (normal, d): flat, its normal agreeing, its
  // centroid within its noise (and `warp` more). `oriented_only`: blocks without a usable normal
  // of their own stay out.
  bool accepts(int block, const Eigen::Vector3d& normal, double d, double warp = 0.0, bool oriented_only = false) const;
  // The plane of an accepted region's whole surface: the blocks around it (trimmed ones too)
  // that lie on it within their noise and kSurfaceWarp join a copy of its blocks, and the plane
  // is refitted to all of them, as a least-squares fit to the whole face would be. Sets
  // (normal, d) and returns true unless nothing joined or the refit turns the normal by more
  // than `max_turn`. The region itself is not changed.
  bool wholeFacePlane(const PlaneRegion& region, const std::vector<char>& taken, double max_turn,
                      Eigen::Vector3d& normal, double& d);
  // True when the blocks whose rays do not graze the plane (under ~6 deg) hold fewer than
  // min_support points.
  bool seenEdgeOn(const std::vector<int>& blocks, const Eigen::Vector3d& normal) const;
  // True when the block centroids bend away from the plane: a quadric fit explains them
  // significantly better (p < 0.001: its chi^2 drop over 3 degrees of freedom against the
  // noise model, or as an F test against their own scatter about the quadric) and its larger
  // principal curvature exceeds what a plane may have (a pillar's, a ball's or a can's side)
  // with a sag over the region's width beyond max_sag (beyond kSurfaceWarp when only the F
  // test finds the bend).
  bool centroidsBend(const std::vector<int>& blocks, const Eigen::Vector3d& normal, double d,
                     double max_sag = kMaxPlaneSag) const;
  // True when the blocks' own normals turn across the region, significantly beyond their
  // measured scatter and by more than a plane's curvature and sag (max_sag) may be (a pillar's
  // or can's side).
  bool normalsTurn(const std::vector<int>& blocks, const Eigen::Vector3d& normal, double max_sag = kMaxPlaneSag) const;
  // True when the region ends where its surface does: of the blocks around it and its sides on
  // the image's edge, under kMaxContinuingShareOfAFace continue it (as continuesAndBends counts
  // them), lie on its plane without a normal of their own to show a crease, or are the image's
  // edge; the rest are creases, depth jumps or no returns. Such a region is a whole face, and a
  // real face bows (kSurfaceWarp); a region that continues is judged with its continuation.
  bool endsWhereItsSurfaceDoes(const std::vector<int>& blocks, const Eigen::Vector3d& normal, double d) const;
  // True when the region did not end where its surface does and that surface bends: half or more
  // of the blocks around it (the image's edge counted as a boundary) continue it (flat, within
  // merge_distance and their noise of its plane, turned less than kCreaseAngle from it), and
  // with them the blocks turn or bend (normalsTurn, centroidsBend). A facet of a ball or a
  // pillar passes those tests alone when correlated depth noise leaves its blocks' normals
  // precise enough to stop the growing at the curve while its sag hides in the noise.
  bool continuesAndBends(const std::vector<int>& blocks, const Eigen::Vector3d& normal, double d) const;
  // Weighted least-squares plane of the blocks' centroids; false when they fix no plane.
  bool fit(const std::vector<int>& blocks, Eigen::Vector3d& normal, double& d) const;
  // The same over the blocks' interior (those whose four neighbours are among them) when it
  // is large enough, else over all of them.
  bool fitInterior(const std::vector<int>& blocks, Eigen::Vector3d& normal, double& d) const;

private:
  // Its ray meets the plane under ~6 deg: its centroid lies on any plane along that ray.
  bool grazes(int block, const Eigen::Vector3d& normal) const;
  // The blocks around `blocks` that continue its surface (flat, on its plane within
  // merge_distance and their noise, turned less than kCreaseAngle) into `continuing`; returns
  // how many blocks and image-edge sides lie around it; in `unoriented_on_plane` how many others
  // lie on the plane as those do but have no informative normal of their own, in
  // `image_edge_sides` how many of its blocks' sides lie on the image's edge.
  size_t continuingBlocks(const std::vector<int>& blocks, const Eigen::Vector3d& normal, double d,
                          std::vector<int>& continuing, size_t* unoriented_on_plane = nullptr,
                          size_t* image_edge_sides = nullptr) const;
  // One breadth-first sweep from `blocks` over neighbours not taken that accepts() admits;
  // returns how many joined.
  size_t sweep(std::vector<int>& blocks, const std::vector<char>& taken, const Eigen::Vector3d& normal, double d,
               double warp = 0.0, bool oriented_only = false);

  const NormalEstimator& grid_;
  const std::vector<BlockInfo>& info_;
  const DetectorParams& params_;
  BlockMarks reached_;           // of sweep
  mutable BlockMarks around_;    // of continuesAndBends
  BlockComponents components_;  // of seedComponents
};

}  // namespace hough_plane_detector
