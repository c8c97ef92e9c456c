#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

#include "hough_plane_detector/core/plane_detector.h"
#include "hough_plane_detector/sim/scene_renderer.h"

using namespace hough_plane_detector;

namespace
{
// One snapped plane's pooled-tilt record in a version-3 file: id, two 3 x 3 informations, four
// vectors, then viewpoint_frames, last_frame and measurements (64 bits each).
constexpr size_t kTiltBytes = 4 + 8 * (2 * 9 + 4 * 3) + 3 * 8;
// A detector that has seen a few frames of the office.
void warmUp(PlaneDetector& detector, int frames)
{
  SceneRenderer renderer(makeOfficeRoom());
  const auto poses = roomTour(40);
  KinectNoise noise;
  for (int f = 0; f < frames; ++f)
  {
    const RenderedFrame frame = renderer.render(poses[f], noise, 70 + f);
    ASSERT_TRUE(detector.processFrame(frame.view(), frame.camera_to_world, f));
  }
}

// A map file's body (without its checksum) as version `version`, with its checksum anew.
std::string withVersion(std::string body, uint32_t version)
{
  std::memcpy(&body[8], &version, sizeof(version));  // the version follows the 8-byte magic
  return PlaneDetector::withMapChecksum(body);
}

void writeFile(const std::string& path, const std::string& bytes)
{
  std::ofstream(path, std::ios::binary) << bytes;
}

void expectSameMap(const PlaneDetector& a, const PlaneDetector& b)
{
  ASSERT_EQ(a.planes().size(), b.planes().size());
  for (size_t i = 0; i < a.planes().size(); ++i)
  {
    EXPECT_EQ(a.planes()[i].id, b.planes()[i].id);
    EXPECT_EQ(a.planes()[i].normal, b.planes()[i].normal);
    EXPECT_EQ(a.planes()[i].d, b.planes()[i].d);
    EXPECT_EQ(a.planes()[i].strength, b.planes()[i].strength);
  }
  EXPECT_EQ(a.globalSpace().chunkCount(), b.globalSpace().chunkCount());
  size_t cells = 0;
  a.globalSpace().forEachNonZero([&](int x, int y, int z, float v) {
    ++cells;
    EXPECT_EQ(b.globalSpace().value(x, y, z), v);
  });
  EXPECT_GT(cells, 0u);
}
}  // namespace

TEST(MapFile, SaveAndLoadRestoreTheMapExactlyAndDetectionGoesOn)
{
  PlaneDetector original{DetectorParams()};
  warmUp(original, 6);
  ASSERT_FALSE(original.planes().empty());
  const std::string path = testing::TempDir() + "hpd_map_roundtrip.map";
  std::string error;
  ASSERT_TRUE(original.saveMap(path, &error)) << error;
  EXPECT_FALSE(std::ifstream(path + ".tmp").good()) << "the temporary file was renamed away";

  PlaneDetector restored{DetectorParams()};
  ASSERT_TRUE(restored.loadMap(path, &error)) << error;
  expectSameMap(original, restored);

  // Both go on identically from the same next frame, ids included.
  SceneRenderer renderer(makeOfficeRoom());
  const RenderedFrame frame = renderer.render(roomTour(40)[6], KinectNoise(), 99);
  ASSERT_TRUE(original.processFrame(frame.view(), frame.camera_to_world, 6));
  ASSERT_TRUE(restored.processFrame(frame.view(), frame.camera_to_world, 6));
  expectSameMap(original, restored);
}

TEST(MapFile, RefusesBrokenOrForeignFilesAndKeepsTheCurrentMap)
{
  PlaneDetector source{DetectorParams()};
  warmUp(source, 4);
  const std::string good = source.serializeMap();

  PlaneDetector target{DetectorParams()};
  warmUp(target, 2);
  const auto planes_before = target.planes();
  const size_t chunks_before = target.globalSpace().chunkCount();
  auto expectUntouched = [&]() {
    ASSERT_EQ(target.planes().size(), planes_before.size());
    for (size_t i = 0; i < planes_before.size(); ++i) EXPECT_EQ(target.planes()[i].d, planes_before[i].d);
    EXPECT_EQ(target.globalSpace().chunkCount(), chunks_before);
  };

  std::string error;
  EXPECT_FALSE(target.loadMap(testing::TempDir() + "does_not_exist.map", &error));
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;

  EXPECT_FALSE(target.deserializeMap("just some text file\n", &error));
  EXPECT_NE(error.find("not a hough_plane_detector map"), std::string::npos) << error;

  EXPECT_FALSE(target.deserializeMap(good.substr(0, good.size() / 2), &error));
  EXPECT_NE(error.find("checksum"), std::string::npos) << error;

  std::string corrupted = good;
  corrupted[good.size() / 2] ^= 0x40;
  EXPECT_FALSE(target.deserializeMap(corrupted, &error));
  EXPECT_NE(error.find("checksum"), std::string::npos) << error;

  std::string other_version = good;
  other_version[8] = 7;  // the version follows the 8-byte magic
  EXPECT_FALSE(target.deserializeMap(other_version, &error));
  EXPECT_NE(error.find("version 7"), std::string::npos) << error;

  DetectorParams coarse;
  coarse.resolution = 512;
  PlaneDetector coarse_detector(coarse);
  EXPECT_FALSE(coarse_detector.deserializeMap(good, &error));
  EXPECT_NE(error.find("angle_step"), std::string::npos) << error;

  const std::string path = testing::TempDir() + "hpd_map_truncated.map";
  writeFile(path, good.substr(0, 100));
  EXPECT_FALSE(target.loadMap(path, &error));
  EXPECT_NE(error.find(path), std::string::npos) << "names the file: " << error;
  expectUntouched();

  EXPECT_TRUE(target.deserializeMap(good, &error)) << error;
  EXPECT_EQ(target.planes().size(), source.planes().size());
}

// Forgetting by evidence: each plane's belief (log-odds, confirmations, contradictions; since
// version 4 its one-surface measurements) is part of the map (format version 2), so a restored map goes on exactly; a version-1 file (no
// beliefs) still loads, its planes unconfirmed, and a version-2 file (no snapped tilts) too.
TEST(MapFile, BeliefsSurviveASaveAndLoadAndVersionOneFilesStillLoad)
{
  DetectorParams evidence;
  evidence.forgetting = kForgetByEvidence;
  PlaneDetector original(evidence);
  warmUp(original, 8);
  int64_t confirmations = 0;
  for (const DetectedPlane& p : original.planes()) confirmations += p.confirmations;
  ASSERT_GT(confirmations, 0) << "eight frames of the office confirmed its planes";
  int64_t one_surface = 0;
  for (const DetectedPlane& p : original.planes()) one_surface += original.map().belief(p.id)->one_surface_measurements;
  ASSERT_GT(one_surface, 0) << "and measured them as one surface each";
  PlaneDetector restored(evidence);
  std::string error;
  ASSERT_TRUE(restored.deserializeMap(original.serializeMap(), &error)) << error;
  SceneRenderer renderer(makeOfficeRoom());
  for (int f = 8; f < 12; ++f)
  {
    const RenderedFrame frame = renderer.render(roomTour(40)[f], KinectNoise(), 99 + f);
    ASSERT_TRUE(original.processFrame(frame.view(), frame.camera_to_world, f));
    ASSERT_TRUE(restored.processFrame(frame.view(), frame.camera_to_world, f));
    expectSameMap(original, restored);
    for (size_t i = 0; i < original.planes().size(); ++i)
    {
      EXPECT_EQ(restored.planes()[i].confirmations, original.planes()[i].confirmations);
      EXPECT_EQ(restored.planes()[i].contradictions, original.planes()[i].contradictions);
      const PlaneBelief* kept = original.map().belief(original.planes()[i].id);
      const PlaneBelief* loaded = restored.map().belief(restored.planes()[i].id);
      ASSERT_TRUE(kept && loaded);
      EXPECT_EQ(loaded->log_odds, kept->log_odds);
      EXPECT_EQ(loaded->one_surface_measurements, kept->one_surface_measurements);
    }
  }

  // Versions 1 and 2: the same bytes without the snapped tilts (version 3), then without the
  // belief section, each with its version number and its checksum (64-bit FNV-1a) anew.
  DetectorParams thinning_params;
  thinning_params.forgetting = kForgetByThinning;  // a map without beliefs, as version 1 wrote
  PlaneDetector thinning{thinning_params};
  warmUp(thinning, 4);
  std::string bytes = thinning.serializeMap();
  bytes.resize(bytes.size() - sizeof(uint64_t));  // the checksum
  // The snapped tilts close the file: a count, then that many records.
  ASSERT_GT(thinning.map().snapTiltRecords(), 0u) << "the office's later frames snap to its known planes";
  const size_t tilt_section = sizeof(uint32_t) + thinning.map().snapTiltRecords() * kTiltBytes;
  bytes.resize(bytes.size() - tilt_section);
  PlaneDetector version_two_reader(evidence);
  ASSERT_TRUE(version_two_reader.deserializeMap(withVersion(bytes, 2), &error)) << error;
  expectSameMap(thinning, version_two_reader);
  bytes.resize(bytes.size() - sizeof(uint32_t));  // a belief count of 0
  bytes = withVersion(bytes, 1);
  PlaneDetector old_reader(evidence);
  ASSERT_TRUE(old_reader.deserializeMap(bytes, &error)) << error;
  expectSameMap(thinning, old_reader);
  for (const DetectedPlane& p : old_reader.planes()) EXPECT_EQ(p.confirmations, 0);
}

// A version-3 file holds each belief without its one-surface measurements (version 4): its
// planes keep the standing they had, every belief counted as measured as one surface once.
TEST(MapFile, VersionThreeBeliefsLoadAsMeasuredOnce)
{
  DetectorParams evidence;
  evidence.forgetting = kForgetByEvidence;
  PlaneDetector original(evidence);
  warmUp(original, 8);
  std::string body = original.serializeMap();
  body.resize(body.size() - sizeof(uint64_t));  // the checksum
  // The beliefs (a count, then id, log-odds, confirmations, contradictions and one-surface
  // measurements each) come just before the snapped tilts, which close the file.
  constexpr size_t kBeliefBytes = 4 + 4 * 8;
  const size_t tilts = sizeof(uint32_t) + original.map().snapTiltRecords() * kTiltBytes;
  const size_t beliefs = original.planes().size();
  const size_t section = body.size() - tilts - sizeof(uint32_t) - beliefs * kBeliefBytes;
  uint32_t count;
  std::memcpy(&count, &body[section], sizeof(count));
  ASSERT_EQ(count, beliefs) << "one belief per plane";
  std::string old = body.substr(0, section + sizeof(uint32_t));
  for (size_t i = 0; i < beliefs; ++i)
    old += body.substr(section + sizeof(uint32_t) + i * kBeliefBytes, kBeliefBytes - 8);
  old += body.substr(body.size() - tilts);
  PlaneDetector restored(evidence);
  std::string error;
  ASSERT_TRUE(restored.deserializeMap(withVersion(old, 3), &error)) << error;
  expectSameMap(original, restored);
  for (const DetectedPlane& plane : original.planes())
  {
    const PlaneBelief* kept = original.map().belief(plane.id);
    const PlaneBelief* loaded = restored.map().belief(plane.id);
    ASSERT_TRUE(kept && loaded);
    EXPECT_EQ(loaded->log_odds, kept->log_odds);
    EXPECT_EQ(loaded->confirmations, kept->confirmations);
    EXPECT_EQ(loaded->one_surface_measurements, 1);
  }
}

// Found by fuzz_map_file: a count far beyond the file's size made the loader allocate for it
// before reading (out of memory). Counts are now checked against the bytes left.
TEST(MapFile, AbsurdCountsAreRefusedBeforeAllocating)
{
  PlaneDetector detector{DetectorParams()};
  warmUp(detector, 2);
  std::string body = detector.serializeMap();
  body.resize(body.size() - sizeof(uint64_t));  // without its checksum
  // magic 8, version 4, three doubles, two int32, next id int32, frame count int64: plane count at 56.
  const size_t plane_count_offset = 8 + 4 + 3 * 8 + 2 * 4 + 4 + 8;
  std::string error;
  std::string absurd = body;
  const uint32_t huge = 0xFFFFFFFFu;
  std::memcpy(&absurd[plane_count_offset], &huge, sizeof(huge));
  PlaneDetector target{DetectorParams()};
  EXPECT_FALSE(target.deserializeMap(PlaneDetector::withMapChecksum(absurd), &error));
  EXPECT_NE(error.find("plane count does not fit"), std::string::npos) << error;
  // The unchanged body with its checksum still loads.
  EXPECT_TRUE(target.deserializeMap(PlaneDetector::withMapChecksum(body), &error)) << error;
}

// The pooled tilts of snapped planes decide where a plane moves: a file whose tilts are not
// finite (NaN would move a plane to a NaN normal) is refused, and the current map stays.
TEST(MapFile, SnappedTiltsThatAreNotFiniteAreRefused)
{
  PlaneDetector source{DetectorParams()};
  warmUp(source, 4);
  ASSERT_GT(source.map().snapTiltRecords(), 0u) << "the office's later frames snap to its known planes";
  std::string body = source.serializeMap();
  body.resize(body.size() - sizeof(uint64_t));  // without its checksum
  // The last record's information(0, 0), after its id: the records close the file.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&body[body.size() - kTiltBytes + 4], &nan, sizeof(nan));
  PlaneDetector target{DetectorParams()};
  warmUp(target, 2);
  const std::string before = target.serializeMap();
  std::string error;
  EXPECT_FALSE(target.deserializeMap(PlaneDetector::withMapChecksum(body), &error));
  EXPECT_NE(error.find("not finite"), std::string::npos) << error;
  EXPECT_EQ(target.serializeMap(), before);
}

TEST(MapFile, SavingToAnUnwritablePlaceFailsCleanly)
{
  PlaneDetector detector{DetectorParams()};
  std::string error;
  EXPECT_FALSE(detector.saveMap("/nonexistent-dir/x.map", &error));
  EXPECT_NE(error.find("cannot write"), std::string::npos) << error;
}

TEST(PlaneExtent, HullCoversTheSeenPartOfTheFloorAndFades)
{
  PlaneDetector detector{DetectorParams()};
  warmUp(detector, 6);
  const DetectedPlane* floor = nullptr;
  for (const auto& p : detector.planes())
    if (std::abs(p.normal.z()) > 0.99 && std::abs(p.d) < 0.02) floor = &p;
  ASSERT_NE(floor, nullptr);
  const auto hull = detector.hull(*floor);
  ASSERT_GE(hull.size(), 3u);
  // Every hull vertex lies on the floor, inside the 6 x 5 m room (plus one cell).
  for (const auto& p : hull)
  {
    EXPECT_NEAR(p.z(), 0.0, 0.03);
    EXPECT_LE(std::abs(p.x()), 3.06);
    EXPECT_LE(std::abs(p.y()), 2.56);
  }
  // Counter-clockwise about the reported normal.
  Eigen::Vector3d area = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < hull.size(); ++i) area += hull[i].cross(hull[(i + 1) % hull.size()]);
  EXPECT_GT(area.dot(floor->normal), 0.5) << "the patch covers at least 0.25 m^2, facing the normal";

  // A cell seen twice outlives one seen once by 1 / fade frames.
  PlaneExtent extent;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  extent.add({1.02, 2.01, 0.0}, up, 0.0, 1, 0.5f);
  extent.add({1.02, 2.01, 0.0}, up, 0.0, 1, 0.5f);
  // A later estimate of the normal a hair off does not turn the extent's cells.
  extent.add({-0.5, 0.3, 0.0}, Eigen::Vector3d(0.001, -0.001, 1.0).normalized(), 0.0, 1, 0.5f);
  EXPECT_EQ(extent.cellCount(), 2u);
  EXPECT_EQ(extent.hull(2, 0.5f).size(), 6u);  // two diagonal squares: a hexagon
  extent.sweep(3, 0.5f);  // the cell seen once has faded, the one seen twice stays
  EXPECT_EQ(extent.cellCount(), 1u);
  const auto square = extent.hull(3, 0.5f);
  ASSERT_EQ(square.size(), 4u);  // one 5 cm square around (1.02, 2.01)
  for (const auto& p : square)
  {
    EXPECT_NEAR(p.x(), 1.025, 0.026);
    EXPECT_NEAR(p.y(), 2.025, 0.026);
  }
  EXPECT_TRUE(extent.hull(10, 0.5f).empty()) << "faded out entirely";
}

// Two tables at one height are one plane of the map with two regions, each within its table;
// one hull would span the gap between them.
TEST(PlaneExtent, TwoCoplanarTablesAreTwoRegionsOfOnePlane)
{
  Scene scene;
  scene.addRectangle({2.0, 0, 0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 3.0, 3.0, "floor");
  scene.addBox({2.2, -0.8, 0.36}, {0.4, 0.4, 0.36}, 0.0, "left");
  scene.addBox({2.2, 0.8, 0.36}, {0.4, 0.4, 0.36}, 0.0, "right");
  const SceneRenderer renderer(scene);
  PlaneDetector detector{DetectorParams()};
  KinectNoise noise;
  for (int f = 0; f < 8; ++f)
  {
    const RenderedFrame frame = renderer.render(lookAt({0.0, 0.05 * f, 1.6}, {2.2, 0.0, 0.5}), noise, 900 + f);
    std::string error;
    ASSERT_TRUE(detector.processFrame(frame.view(), frame.camera_to_world, 0.1 * f, &error)) << error;
  }
  const DetectedPlane* tops = nullptr;
  for (const auto& p : detector.planes())
    if (std::abs(p.normal.z()) > 0.999 && std::abs(std::abs(p.d) - 0.72) < 0.02) tops = &p;
  ASSERT_NE(tops, nullptr) << "the tables' plane";
  const auto regions = detector.regions(*tops);
  ASSERT_EQ(regions.size(), 2u);
  bool left = false, right = false;
  for (const auto& region : regions)
  {
    double y_min = 1e9, y_max = -1e9;
    for (const auto& v : region)
    {
      EXPECT_NEAR(v.z(), 0.72, 0.03);
      EXPECT_NEAR(v.x(), 2.2, 0.46);
      y_min = std::min(y_min, v.y());
      y_max = std::max(y_max, v.y());
    }
    left |= y_min > -1.26 && y_max < -0.34;
    right |= y_min > 0.34 && y_max < 1.26;
  }
  EXPECT_TRUE(left && right) << "each region lies on its own table";
  double hull_y_min = 1e9, hull_y_max = -1e9;
  for (const auto& v : detector.hull(*tops))
  {
    hull_y_min = std::min(hull_y_min, v.y());
    hull_y_max = std::max(hull_y_max, v.y());
  }
  EXPECT_LT(hull_y_min, -0.4);
  EXPECT_GT(hull_y_max, 0.4) << "the single hull spans the gap the regions leave";
}
