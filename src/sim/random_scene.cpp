#include "hough_plane_detector/sim/random_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace hough_plane_detector
{

// Written down before any threshold was chosen on random scenes (see the header).
const std::vector<uint32_t> kHeldOutSeeds = {101, 102, 103, 104, 105, 106, 107, 108, 109, 110,
                                             111, 112, 113, 114, 115, 116, 117, 118, 119, 120};
namespace
{
std::vector<uint32_t> seedRange(uint32_t first, uint32_t last)
{
  std::vector<uint32_t> seeds;
  for (uint32_t seed = first; seed <= last; ++seed) seeds.push_back(seed);
  return seeds;
}
}  // namespace

// Written down on 2026-12-03, before any run on them: 20 seeds left the false-plane rate
// uncertain by about half its value (6 false planes in 180 frames).
const std::vector<uint32_t> kSecondHeldOutSeeds = seedRange(121, 160);
// Written down on 2026-12-03, before any run on them: 101-160 had been looked at (their false
// planes' origins) while the close-surface peaks were developed, so that rule's verdict needed
// rooms no one had seen.
const std::vector<uint32_t> kThirdHeldOutSeeds = seedRange(501, 540);
const std::vector<uint32_t> kTuningSeeds = {901, 902, 903, 904, 905, 906, 907, 908};
const std::vector<uint32_t> kDevelopmentSeeds = {950, 951, 952, 953, 954, 955, 956, 957,
                                                 958, 959, 960, 961, 962, 963, 964, 965};
const std::vector<uint32_t> kSecondDevelopmentSeeds = seedRange(300, 339);
const std::vector<uint32_t> kThirdDevelopmentSeeds = seedRange(600, 679);
// Written down on 2026-12-07 as development rooms toured at C = 1 as the held-out verdict is:
// false planes are rare events, and 120 development rooms at C = 1 left a rule's cost unseen
// that 100 held-out rooms showed.
const std::vector<uint32_t> kFourthDevelopmentSeeds = seedRange(700, 899);

namespace
{
constexpr double kPi = 3.14159265358979323846;

class Builder
{
public:
  Builder(uint32_t seed) : rng_(seed) {}

  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool chance(double p) { return uniform(0.0, 1.0) < p; }

  // A free spot for a footprint of this radius inside the room, clear of the walls by `margin`,
  // of earlier footprints and of the camera's disc; false when none was found.
  bool place(double radius, double margin, Eigen::Vector2d& at)
  {
    for (int attempt = 0; attempt < 60; ++attempt)
    {
      const Eigen::Vector2d p(uniform(-half_w + margin + radius, half_w - margin - radius),
                              uniform(-half_d + margin + radius, half_d - margin - radius));
      if ((p - camera_centre).norm() < camera_clear + radius) continue;
      bool clear = true;
      for (const auto& [centre, r] : footprints) clear &= (p - centre).norm() > r + radius + 0.1;
      if (!clear) continue;
      footprints.emplace_back(p, radius);
      at = p;
      return true;
    }
    return false;
  }

  std::mt19937 rng_;
  double half_w = 0, half_d = 0;
  Eigen::Vector2d camera_centre = Eigen::Vector2d::Zero();
  double camera_clear = 0;
  std::vector<std::pair<Eigen::Vector2d, double>> footprints;
};

const Eigen::Vector3d kX = Eigen::Vector3d::UnitX(), kY = Eigen::Vector3d::UnitY(), kZ = Eigen::Vector3d::UnitZ();

void addRoom(Builder& b, Scene& s, double h, std::string& what)
{
  const double w = b.half_w, d = b.half_d;
  s.addRectangle({0, 0, 0}, kX, kY, w, d, "floor");
  s.addRectangle({w, 0, h / 2}, kY, kZ, d, h / 2, "wall_east");
  s.addRectangle({-w, 0, h / 2}, kY, kZ, d, h / 2, "wall_west");
  s.addRectangle({0, d, h / 2}, kX, kZ, w, h / 2, "wall_north");
  s.addRectangle({0, -d, h / 2}, kX, kZ, w, h / 2, "wall_south");
  if (!b.chance(0.5))
  {
    s.addRectangle({0, 0, h}, kX, kY, w, d, "ceiling");
    return;
  }
  // A ceiling sloping down to the north wall over `run`, flat elsewhere.
  const double slope = b.uniform(20.0, 45.0) * kPi / 180.0;
  const double run = std::min(b.uniform(0.8, 2.0), std::min(d, (h - 1.4) / std::tan(slope)));
  s.addRectangle({0, -run / 2, h}, kX, kY, w, d - run / 2, "ceiling");
  const Eigen::Vector3d down_slope(0, std::cos(slope), -std::sin(slope));
  const double length = run / std::cos(slope);
  s.addRectangle(Eigen::Vector3d(0, d - run, h) + 0.5 * length * down_slope, kX, down_slope, w, length / 2,
                 "ceiling_slope");
  char text[64];
  std::snprintf(text, sizeof(text), ", ceiling sloped %.0f deg", slope * 180.0 / kPi);
  what += text;
}

void addStairs(Builder& b, Scene& s, std::string& what)
{
  const int steps = b.integer(3, 6);
  const double rise = b.uniform(0.12, 0.2), run = b.uniform(0.25, 0.35), width = b.uniform(0.8, 1.2);
  // Against the east wall, rising toward it.
  const double y = b.uniform(-b.half_d + width / 2 + 0.1, b.half_d - width / 2 - 0.1);
  const Eigen::Vector2d footprint(b.half_w - steps * run / 2, y);
  const double radius = 0.5 * std::hypot(steps * run, width);
  if ((footprint - b.camera_centre).norm() < b.camera_clear + radius) return;
  b.footprints.emplace_back(footprint, radius);
  for (int i = 0; i < steps; ++i)
  {
    const double top = (i + 1) * rise;
    s.addBox({b.half_w - (steps - i - 0.5) * run, y, top / 2}, {run / 2, width / 2, top / 2}, 0.0, "stair" + std::to_string(i));
  }
  char text[96];
  std::snprintf(text, sizeof(text), ", %d stairs %.0f/%.0f cm", steps, rise * 100, run * 100);
  what += text;
}

void addRamp(Builder& b, Scene& s, std::string& what)
{
  const double slope = b.uniform(5.0, 20.0) * kPi / 180.0;
  const double length = b.uniform(1.5, 2.5), width = b.uniform(1.0, 1.5);
  const double heading = b.integer(0, 3) * kPi / 2;
  Eigen::Vector2d at;
  if (!b.place(0.5 * std::hypot(length, width), 0.1, at)) return;
  const Eigen::Vector3d along(std::cos(heading), std::sin(heading), 0), side(-std::sin(heading), std::cos(heading), 0);
  const Eigen::Vector3d up = std::cos(slope) * along + std::sin(slope) * kZ;
  const Eigen::Vector3d start = Eigen::Vector3d(at.x(), at.y(), 0.0) - 0.5 * length * std::cos(slope) * along;
  s.addRectangle(start + 0.5 * length * up, up, side, length / 2, width / 2, "ramp");
  char text[64];
  std::snprintf(text, sizeof(text), ", ramp %.0f deg", slope * 180.0 / kPi);
  what += text;
}

void addShelving(Builder& b, Scene& s, std::string& what)
{
  // Against the west wall: side panels and boards 30-40 cm apart (top and underside each).
  const double width = b.uniform(0.8, 1.2), depth = b.uniform(0.3, 0.4), gap = b.uniform(0.3, 0.4);
  const int boards = b.integer(3, 5);
  const double y = b.uniform(-b.half_d + width / 2 + 0.1, b.half_d - width / 2 - 0.1);
  const Eigen::Vector2d footprint(-b.half_w + depth / 2, y);
  if ((footprint - b.camera_centre).norm() < b.camera_clear + width / 2) return;
  b.footprints.emplace_back(footprint, 0.5 * std::hypot(width, depth));
  const double height = 0.1 + (boards - 1) * gap + 0.05;
  const double x = -b.half_w + depth / 2;
  for (int side = -1; side <= 1; side += 2)
    s.addRectangle({x, y + side * width / 2, height / 2}, kX, kZ, depth / 2, height / 2, "shelf_side");
  for (int i = 0; i < boards; ++i)
  {
    const double z = 0.1 + i * gap;
    s.addRectangle({x, y, z + 0.02}, kX, kY, depth / 2, width / 2, "shelf_board_top" + std::to_string(i));
    s.addRectangle({x, y, z}, kX, kY, depth / 2, width / 2, "shelf_board_under" + std::to_string(i));
  }
  char text[64];
  std::snprintf(text, sizeof(text), ", shelving of %d boards %.0f cm apart", boards, gap * 100);
  what += text;
}

void addFurniture(Builder& b, Scene& s, std::string& what)
{
  const int tables = b.integer(1, 2);
  int placed_tables = 0, boxes = 0, stacked = 0;
  for (int i = 0; i < tables; ++i)
  {
    const double half_x = b.uniform(0.4, 0.8), half_y = b.uniform(0.3, 0.45), top = b.uniform(0.7, 0.8);
    Eigen::Vector2d at;
    if (!b.place(std::hypot(half_x, half_y), 0.1, at)) continue;
    s.addBox({at.x(), at.y(), top / 2}, {half_x, half_y, top / 2}, b.uniform(0.0, kPi), "table" + std::to_string(i));
    ++placed_tables;
  }
  const int crates = b.integer(2, 5);
  for (int i = 0; i < crates; ++i)
  {
    const Eigen::Vector3d half(b.uniform(0.1, 0.25), b.uniform(0.1, 0.25), b.uniform(0.1, 0.25));
    Eigen::Vector2d at;
    if (!b.place(half.head<2>().norm(), 0.05, at)) continue;
    const std::string name = "box" + std::to_string(i);
    s.addBox({at.x(), at.y(), half.z()}, half, b.uniform(0.0, kPi), name);
    ++boxes;
    if (!b.chance(0.4)) continue;
    const Eigen::Vector3d upper(half.x() * b.uniform(0.5, 0.9), half.y() * b.uniform(0.5, 0.9), b.uniform(0.08, 0.2));
    s.addBox({at.x(), at.y(), 2 * half.z() + upper.z()}, upper, b.uniform(0.0, kPi), name + "_stacked");
    ++stacked;
  }
  char text[96];
  std::snprintf(text, sizeof(text), ", %d tables, %d boxes (%d stacked)", placed_tables, boxes, stacked);
  what += text;
}

void addDoor(Builder& b, Scene& s, std::string& what)
{
  // Hinged on the south wall, opened into the room.
  const double opened = b.uniform(30.0, 80.0) * kPi / 180.0;
  const double hinge_x = b.uniform(-b.half_w + 0.2, b.half_w - 1.1);
  const Eigen::Vector3d leaf(std::cos(opened), std::sin(opened), 0);
  const Eigen::Vector3d hinge(hinge_x, -b.half_d, 0.0);
  const Eigen::Vector2d footprint = (hinge + 0.45 * leaf).head<2>();
  if ((footprint - b.camera_centre).norm() < b.camera_clear + 0.45) return;
  b.footprints.emplace_back(footprint, 0.45);
  s.addRectangle(hinge + 0.45 * leaf + Eigen::Vector3d(0, 0, 1.0), leaf, kZ, 0.45, 1.0, "door");
  char text[64];
  std::snprintf(text, sizeof(text), ", door open %.0f deg", opened * 180.0 / kPi);
  what += text;
}

void addCurvedClutter(Builder& b, Scene& s, std::string& what)
{
  int cylinders = 0, spheres = 0;
  for (int i = b.integer(1, 3); i > 0; --i)
  {
    const double r = b.uniform(0.1, 0.35);
    Eigen::Vector2d at;
    if (!b.place(r, 0.05, at)) continue;
    s.cylinders.push_back({{at.x(), at.y(), 0.0}, r, b.uniform(0.5, 2.0)});
    ++cylinders;
  }
  for (int i = b.integer(0, 2); i > 0; --i)
  {
    const double r = b.uniform(0.15, 0.4);
    Eigen::Vector2d at;
    if (!b.place(r, 0.05, at)) continue;
    s.spheres.push_back({{at.x(), at.y(), r}, r});
    ++spheres;
  }
  char text[64];
  std::snprintf(text, sizeof(text), ", %d cylinders, %d balls", cylinders, spheres);
  what += text;
}

// Moves the whole room (built about the origin, axis-aligned) to its place and yaw.
void transformScene(Scene& s, const Eigen::Isometry3d& t)
{
  for (SceneRectangle& r : s.rectangles)
  {
    r.center = t * r.center;
    r.axis_u = t.linear() * r.axis_u;
    r.axis_v = t.linear() * r.axis_v;
  }
  for (SceneCylinder& c : s.cylinders) c.base = t * c.base;  // a yaw keeps them vertical
  for (SceneSphere& p : s.spheres) p.center = t * p.center;
}
}  // namespace

RandomScene makeRandomScene(uint32_t seed, int frames)
{
  Builder b(seed);
  RandomScene out;
  out.seed = seed;
  b.half_w = b.uniform(2.0, 4.0);
  b.half_d = b.uniform(1.75, 3.5);
  const double height = b.uniform(2.4, 3.2);
  const double yaw = b.uniform(0.0, kPi / 2);
  const Eigen::Vector3d offset(b.uniform(-2.0, 2.0), b.uniform(-2.0, 2.0), 0.0);
  out.noise = b.uniform(0.5, 2.0);
  // The camera circles a spot near the middle; objects keep out of its way.
  const double path_radius = b.uniform(0.3, 0.8);
  b.camera_centre = Eigen::Vector2d(b.uniform(-0.3, 0.3) * b.half_w, b.uniform(-0.3, 0.3) * b.half_d);
  b.camera_clear = path_radius + 0.6;
  const double eye_height = b.uniform(0.8, 1.6), pitch = b.uniform(10.0, 35.0) * kPi / 180.0;
  const double look_offset = b.uniform(0.2, 0.8), phase = b.uniform(0.0, 2 * kPi);

  char text[160];
  std::snprintf(text, sizeof(text), "%.1f x %.1f x %.1f m, yaw %.0f deg, C = %.2f, camera %.2f m high", 2 * b.half_w,
                2 * b.half_d, height, yaw * 180.0 / kPi, out.noise, eye_height);
  out.description = text;
  addRoom(b, out.scene, height, out.description);
  if (b.chance(0.5)) addStairs(b, out.scene, out.description);
  if (b.chance(0.5)) addRamp(b, out.scene, out.description);
  if (b.chance(0.6)) addShelving(b, out.scene, out.description);
  if (b.chance(0.5)) addDoor(b, out.scene, out.description);
  addFurniture(b, out.scene, out.description);
  addCurvedClutter(b, out.scene, out.description);

  Eigen::Isometry3d place = Eigen::Isometry3d::Identity();
  place.linear() = Eigen::AngleAxisd(yaw, kZ).toRotationMatrix();
  place.translation() = offset;
  transformScene(out.scene, place);
  for (int i = 0; i < frames; ++i)
  {
    const double a = phase + 2.0 * kPi * i / std::max(1, frames);
    const Eigen::Vector3d eye(b.camera_centre.x() + path_radius * std::cos(a),
                              b.camera_centre.y() + path_radius * std::sin(a), eye_height);
    const Eigen::Vector3d target = eye + Eigen::Vector3d(std::cos(a + look_offset), std::sin(a + look_offset), -std::tan(pitch));
    out.poses.push_back(place * lookAt(eye, target));
  }
  return out;
}

}  // namespace hough_plane_detector
