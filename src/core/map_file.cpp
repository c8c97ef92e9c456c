// Saving and loading the persistent map (PlaneMap), and the detector's file versions of it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/core/plane_map.h"

namespace hough_plane_detector
{

namespace
{
constexpr char kMagic[8] = {'H', 'P', 'D', 'M', 'A', 'P', '\n', '\0'};
// 2: plane beliefs (forgetting by evidence) after the extents; 3: the snapped tilts after them;
// 4: each belief's one-surface measurements.
constexpr uint32_t kVersion = 4;
constexpr uint32_t kOldestReadVersion = 1;  // 1: no beliefs; its planes load unconfirmed

// A map's keys in order: a map file does not depend on hash order.
template <class Map>
std::vector<int> sortedIds(const Map& by_id)
{
  std::vector<int> ids;
  for (const auto& entry : by_id) ids.push_back(entry.first);
  std::sort(ids.begin(), ids.end());
  return ids;
}

uint64_t fnv1a(const char* data, size_t size)
{
  uint64_t hash = 1469598103934665603ull;
  for (size_t i = 0; i < size; ++i)
  {
    hash ^= static_cast<unsigned char>(data[i]);
    hash *= 1099511628211ull;
  }
  return hash;
}

class Writer
{
public:
  template <class T>
  void put(const T& value)
  {
    bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void putBytes(const void* data, size_t size) { bytes.append(static_cast<const char*>(data), size); }
  std::string bytes;
};

class Reader
{
public:
  Reader(const std::string& bytes, size_t end) : bytes_(bytes), end_(end) {}
  template <class T>
  bool get(T& value)
  {
    return getBytes(&value, sizeof(T));
  }
  bool getBytes(void* out, size_t size)
  {
    if (pos_ + size > end_) return false;
    std::memcpy(out, bytes_.data() + pos_, size);
    pos_ += size;
    return true;
  }
  size_t position() const { return pos_; }
  size_t remaining() const { return end_ - pos_; }

private:
  const std::string& bytes_;
  size_t end_;
  size_t pos_ = 0;
};
}  // namespace

std::string PlaneMap::withChecksum(const std::string& bytes)
{
  Writer w;
  w.bytes = bytes;
  w.put(fnv1a(bytes.data(), bytes.size()));
  return w.bytes;
}

std::string PlaneMap::serialize() const
{
  Writer w;
  w.putBytes(kMagic, sizeof(kMagic));
  w.put(kVersion);
  w.put(param_.angleStep());
  w.put(param_.dStep());
  w.put(param_.maxDistance());
  w.put(static_cast<int32_t>(param_.sizeAngle()));
  w.put(static_cast<int32_t>(param_.sizeD()));
  w.put(static_cast<int32_t>(next_id_));
  w.put(frame_count_);
  w.put(static_cast<uint32_t>(planes_.size()));
  for (const DetectedPlane& p : planes_)
  {
    w.put(static_cast<int32_t>(p.id));
    for (int i = 0; i < 3; ++i) w.put(p.normal(i));
    w.put(p.d);
    w.put(p.strength);
    w.put(static_cast<int32_t>(p.support));
    w.put(p.first_seen);
    w.put(p.last_seen);
    for (int i = 0; i < 3; ++i) w.put(p.hough(i));
  }
  const auto& chunks = global_.allocatedChunkIndices();
  w.put(static_cast<uint32_t>(chunks.size()));
  for (int index : chunks)
  {
    w.put(static_cast<int32_t>(index));
    w.putBytes(global_.chunkData(index), sizeof(float) * SparseHoughSpace::kChunkCells);
  }
  w.put(static_cast<uint32_t>(extents_.size()));
  for (int id : sortedIds(extents_))
  {
    const PlaneExtent& extent = extents_.at(id);
    const auto cells = extent.cells();
    w.put(static_cast<int32_t>(id));
    const PlaneBasis basis = extent.basis() ? *extent.basis() : PlaneBasis(Eigen::Vector3d::UnitZ(), 0.0);
    for (const Eigen::Vector3d* axis : {&basis.origin, &basis.u, &basis.v})
      for (int i = 0; i < 3; ++i) w.put((*axis)(i));
    w.put(static_cast<uint32_t>(cells.size()));
    for (const auto& cell : cells)
    {
      w.put(cell.first.first);
      w.put(cell.first.second);
      w.put(cell.second.weight);
      w.put(cell.second.seen);
    }
  }
  const std::vector<int> belief_ids = sortedIds(beliefs_);
  w.put(static_cast<uint32_t>(belief_ids.size()));
  for (int id : belief_ids)
  {
    const PlaneBelief& belief = beliefs_.at(id);
    w.put(static_cast<int32_t>(id));
    w.put(belief.log_odds);
    w.put(belief.confirmations);
    w.put(belief.contradictions);
    w.put(belief.one_surface_measurements);
  }
  const std::vector<int> tilt_ids = sortedIds(snap_tilts_);
  w.put(static_cast<uint32_t>(tilt_ids.size()));
  for (int id : tilt_ids)
  {
    const SnapTilts& tilts = snap_tilts_.at(id);
    w.put(static_cast<int32_t>(id));
    for (const Eigen::Matrix3d* m : {&tilts.information, &tilts.viewpoint_information})
      for (int i = 0; i < 9; ++i) w.put((*m)(i));
    for (const Eigen::Vector3d* v : {&tilts.weighted_tilt, &tilts.viewpoint_weighted_tilt, &tilts.viewpoint, &tilts.centroid_sum})
      for (int i = 0; i < 3; ++i) w.put((*v)(i));
    w.put(tilts.viewpoint_frames);
    w.put(tilts.last_frame);
    w.put(tilts.measurements);
  }
  return withChecksum(w.bytes);
}

namespace
{
// The parts of a map file after its header, each read whole or not at all; "" when read.
std::string readPlanes(Reader& r, std::vector<DetectedPlane>& planes)
{
  uint32_t plane_count;
  if (!r.get(plane_count)) return "map header is truncated";
  // Counts are checked against the bytes left before anything is allocated for them.
  constexpr size_t kPlaneBytes = 4 + 3 * 8 + 8 + 8 + 4 + 8 + 8 + 3 * 8;
  if (plane_count > r.remaining() / kPlaneBytes) return "map plane count does not fit the file (truncated?)";
  planes.resize(plane_count);
  for (DetectedPlane& p : planes)
  {
    int32_t id = 0, support = 0;  // used only when read (`ok`); zeroed for -Wmaybe-uninitialized
    bool ok = r.get(id);
    for (int i = 0; i < 3; ++i) ok = ok && r.get(p.normal(i));
    ok = ok && r.get(p.d) && r.get(p.strength) && r.get(support) && r.get(p.first_seen) && r.get(p.last_seen);
    for (int i = 0; i < 3; ++i) ok = ok && r.get(p.hough(i));
    if (!ok) return "map planes are truncated";
    p.id = id;
    p.support = support;
  }
  return "";
}

std::string readChunks(Reader& r, size_t top_level, std::vector<std::pair<int32_t, std::vector<float>>>& chunks)
{
  uint32_t chunk_count;
  if (!r.get(chunk_count)) return "map chunk list is truncated";
  constexpr size_t kChunkBytes = 4 + sizeof(float) * SparseHoughSpace::kChunkCells;
  if (chunk_count > r.remaining() / kChunkBytes) return "map chunk count does not fit the file (truncated?)";
  chunks.resize(chunk_count);
  for (auto& chunk : chunks)
  {
    chunk.second.resize(SparseHoughSpace::kChunkCells);
    if (!r.get(chunk.first) || !r.getBytes(chunk.second.data(), sizeof(float) * SparseHoughSpace::kChunkCells))
      return "map chunks are truncated";
    if (chunk.first < 0 || static_cast<size_t>(chunk.first) >= top_level)
      return "map chunk index " + std::to_string(chunk.first) + " is outside the Hough space";
  }
  return "";
}

std::string readExtents(Reader& r, std::unordered_map<int, PlaneExtent>& extents)
{
  uint32_t extent_count;
  if (!r.get(extent_count)) return "map extents are truncated";
  for (uint32_t i = 0; i < extent_count; ++i)
  {
    int32_t id;
    uint32_t cell_count;
    Eigen::Vector3d axes[3];
    bool ok = r.get(id);
    for (auto& axis : axes)
      for (int i = 0; i < 3; ++i) ok = ok && r.get(axis(i));
    if (!ok || !r.get(cell_count) || cell_count > PlaneExtent::kMaxCells) return "map extents are truncated";
    PlaneExtent& extent = extents[id];
    extent.setBasis(PlaneBasis(axes[0], axes[1], axes[2]));
    for (uint32_t c = 0; c < cell_count; ++c)
    {
      int32_t x, y;
      PlaneExtent::Cell cell;
      if (!r.get(x) || !r.get(y) || !r.get(cell.weight) || !r.get(cell.seen)) return "map extents are truncated";
      extent.setCell(x, y, cell);
    }
  }
  return "";
}

std::string readBeliefs(Reader& r, uint32_t version, std::unordered_map<int, PlaneBelief>& beliefs)
{
  uint32_t belief_count;
  const size_t belief_bytes = version >= 4 ? 4 + 8 + 8 + 8 + 8 : 4 + 8 + 8 + 8;
  if (!r.get(belief_count) || belief_count > r.remaining() / belief_bytes) return "map beliefs are truncated";
  for (uint32_t i = 0; i < belief_count; ++i)
  {
    int32_t id;
    PlaneBelief belief;
    if (!r.get(id) || !r.get(belief.log_odds) || !r.get(belief.confirmations) || !r.get(belief.contradictions))
      return "map beliefs are truncated";
    // An older map kept its planes by depth confirmations alone: they keep that standing.
    belief.one_surface_measurements = 1;
    if (version >= 4 && !r.get(belief.one_surface_measurements)) return "map beliefs are truncated";
    if (belief.confirmations < 0 || belief.contradictions < 0 || belief.one_surface_measurements < 0)
      return "map beliefs have a negative count";
    beliefs[id] = belief;
  }
  return "";
}

std::string readSnapTilts(Reader& r, std::unordered_map<int, SnapTilts>& snap_tilts)
{
  uint32_t count;
  constexpr size_t kTiltBytes = 4 + 8 * (2 * 9 + 4 * 3) + 3 * 8;
  if (!r.get(count) || count > r.remaining() / kTiltBytes) return "map snapped tilts are truncated";
  for (uint32_t n = 0; n < count; ++n)
  {
    int32_t id;
    SnapTilts tilts;
    bool ok = r.get(id);
    for (Eigen::Matrix3d* m : {&tilts.information, &tilts.viewpoint_information})
      for (int i = 0; i < 9; ++i) ok = ok && r.get((*m)(i));
    for (Eigen::Vector3d* v : {&tilts.weighted_tilt, &tilts.viewpoint_weighted_tilt, &tilts.viewpoint, &tilts.centroid_sum})
      for (int i = 0; i < 3; ++i) ok = ok && r.get((*v)(i));
    ok = ok && r.get(tilts.viewpoint_frames) && r.get(tilts.last_frame) && r.get(tilts.measurements);
    if (!ok) return "map snapped tilts are truncated";
    if (tilts.viewpoint_frames < 0 || tilts.measurements < 0) return "map snapped tilts have a negative count";
    if (!tilts.information.allFinite() || !tilts.viewpoint_information.allFinite() || !tilts.weighted_tilt.allFinite() ||
        !tilts.viewpoint_weighted_tilt.allFinite() || !tilts.viewpoint.allFinite() || !tilts.centroid_sum.allFinite())
      return "map snapped tilts are not finite";
    snap_tilts[id] = tilts;
  }
  return "";
}
}  // namespace

bool PlaneMap::deserialize(const std::string& bytes, std::string* error)
{
  auto fail = [error](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (bytes.size() < sizeof(kMagic) + sizeof(uint32_t) + sizeof(uint64_t) ||
      std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    return fail("not a hough_plane_detector map (no HPDMAP header)");
  Reader r(bytes, bytes.size() - sizeof(uint64_t));
  char magic[sizeof(kMagic)];
  uint32_t version = 0;
  r.getBytes(magic, sizeof(magic));
  r.get(version);
  if (version < kOldestReadVersion || version > kVersion)
    return fail("map format version " + std::to_string(version) + " is not a supported version (" +
                std::to_string(kOldestReadVersion) + " to " + std::to_string(kVersion) + ")");
  uint64_t stored_checksum;
  std::memcpy(&stored_checksum, bytes.data() + bytes.size() - sizeof(uint64_t), sizeof(uint64_t));
  if (stored_checksum != fnv1a(bytes.data(), bytes.size() - sizeof(uint64_t)))
    return fail("map checksum does not match: the file is truncated or corrupted");

  double angle_step, d_step, max_distance;
  int32_t size_angle, size_d, next_id;
  int64_t frame_count;
  if (!r.get(angle_step) || !r.get(d_step) || !r.get(max_distance) || !r.get(size_angle) || !r.get(size_d) ||
      !r.get(next_id) || !r.get(frame_count))
    return fail("map header is truncated");
  if (std::abs(angle_step - param_.angleStep()) > 1e-12 || std::abs(d_step - param_.dStep()) > 1e-12 ||
      std::abs(max_distance - param_.maxDistance()) > 1e-12 || size_angle != param_.sizeAngle() ||
      size_d != param_.sizeD())
  {
    std::ostringstream what;
    what << "map was built with angle_step " << angle_step << ", d_step " << d_step << ", max_distance "
         << max_distance << " (" << size_angle << " x " << size_angle << " x " << size_d
         << " cells); the detector has angle_step " << param_.angleStep() << ", d_step " << param_.dStep()
         << ", max_distance " << param_.maxDistance() << ", blur and peak windows as configured";
    return fail(what.str());
  }
  std::vector<DetectedPlane> planes;
  std::vector<std::pair<int32_t, std::vector<float>>> chunks;
  std::unordered_map<int, PlaneExtent> extents;
  std::unordered_map<int, PlaneBelief> beliefs;
  std::unordered_map<int, SnapTilts> snap_tilts;
  std::string problem = readPlanes(r, planes);
  if (problem.empty()) problem = readChunks(r, global_.topLevelCount(), chunks);
  if (problem.empty()) problem = readExtents(r, extents);
  if (problem.empty() && version >= 2) problem = readBeliefs(r, version, beliefs);
  if (problem.empty() && version >= 3) problem = readSnapTilts(r, snap_tilts);
  if (!problem.empty()) return fail(problem);
  if (r.position() != bytes.size() - sizeof(uint64_t)) return fail("map has trailing bytes");

  // Everything read and checked: only now replace the state.
  global_.clear();
  for (const auto& chunk : chunks)
    std::memcpy(global_.allocateChunk(chunk.first), chunk.second.data(), sizeof(float) * SparseHoughSpace::kChunkCells);
  planes_ = planes;
  for (DetectedPlane& plane : planes_)
  {
    const auto it = beliefs.find(plane.id);
    plane.confirmations = it != beliefs.end() ? it->second.confirmations : 0;
    plane.contradictions = it != beliefs.end() ? it->second.contradictions : 0;
  }
  extents_.swap(extents);
  beliefs_.swap(beliefs);
  snap_tilts_.swap(snap_tilts);
  first_sights_.clear();  // of a frame before the load: no frame of this map
  next_id_ = next_id;
  frame_count_ = frame_count;
  return true;
}

std::string PlaneDetector::withMapChecksum(const std::string& bytes) { return PlaneMap::withChecksum(bytes); }

std::string PlaneDetector::serializeMap() const { return map_.serialize(); }

bool PlaneDetector::deserializeMap(const std::string& bytes, std::string* error)
{
  if (!map_.deserialize(bytes, error)) return false;
  // The last frame's labels name planes of the old map.
  frame_.samples.clear();
  labels_ = FrameLabels();
  return true;
}

bool PlaneDetector::saveMap(const std::string& path, std::string* error) const
{
  const std::string bytes = serializeMap();
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out || !out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())) || !out.flush())
    {
      if (error) *error = "cannot write " + tmp;
      std::remove(tmp.c_str());
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
  {
    if (error) *error = "cannot rename " + tmp + " to " + path;
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

bool PlaneDetector::loadMap(const std::string& path, std::string* error)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    if (error) *error = "cannot open " + path;
    return false;
  }
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string why;
  if (!deserializeMap(bytes, &why))
  {
    if (error) *error = path + ": " + why;
    return false;
  }
  return true;
}

}  // namespace hough_plane_detector
