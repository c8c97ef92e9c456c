#include "hough_plane_detector/sim/scene_renderer.h"

#include "hough_plane_detector/core/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace hough_plane_detector
{

namespace
{
constexpr double kPi = 3.14159265358979323846;
const float kNaN = std::numeric_limits<float>::quiet_NaN();
}  // namespace

void Scene::addRectangle(const Eigen::Vector3d& center, const Eigen::Vector3d& axis_u, const Eigen::Vector3d& axis_v,
                         double half_u, double half_v, const std::string& name)
{
  rectangles.push_back(SceneRectangle{center, axis_u.normalized(), axis_v.normalized(), half_u, half_v, name});
}

void Scene::addBox(const Eigen::Vector3d& center, const Eigen::Vector3d& half, double yaw, const std::string& name)
{
  const Eigen::Vector3d ex(std::cos(yaw), std::sin(yaw), 0), ey(-std::sin(yaw), std::cos(yaw), 0), ez(0, 0, 1);
  addRectangle(center + half.z() * ez, ex, ey, half.x(), half.y(), name + "_top");
  addRectangle(center + half.x() * ex, ey, ez, half.y(), half.z(), name + "_front");
  addRectangle(center - half.x() * ex, ey, ez, half.y(), half.z(), name + "_back");
  addRectangle(center + half.y() * ey, ex, ez, half.x(), half.z(), name + "_left");
  addRectangle(center - half.y() * ey, ex, ez, half.x(), half.z(), name + "_right");
}

void Scene::addRoom(double half_x, double half_y, double height)
{
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  addRectangle({0, 0, 0}, ex, ey, half_x, half_y, "floor");
  addRectangle({0, 0, height}, ex, ey, half_x, half_y, "ceiling");
  addRectangle({half_x, 0, height / 2}, ey, ez, half_y, height / 2, "wall_east");
  addRectangle({-half_x, 0, height / 2}, ey, ez, half_y, height / 2, "wall_west");
  addRectangle({0, half_y, height / 2}, ex, ez, half_x, height / 2, "wall_north");
  addRectangle({0, -half_y, height / 2}, ex, ez, half_x, height / 2, "wall_south");
}

std::vector<TruePlane> Scene::truePlanes(std::vector<int>* rectangle_plane) const
{
  std::vector<TruePlane> planes;
  if (rectangle_plane) rectangle_plane->clear();
  for (const auto& r : rectangles)
  {
    const Eigen::Vector3d n = r.axis_u.cross(r.axis_v).normalized();
    const double d = -n.dot(r.center);
    int found = -1;
    for (size_t i = 0; i < planes.size() && found < 0; ++i)
    {
      const double s = planes[i].normal.dot(n) >= 0 ? 1.0 : -1.0;
      if ((planes[i].normal - s * n).norm() < 1e-6 && std::abs(planes[i].d - s * d) < 1e-6) found = static_cast<int>(i);
    }
    if (found < 0)
    {
      found = static_cast<int>(planes.size());
      planes.push_back(TruePlane{n, d, r.name});
    }
    if (rectangle_plane) rectangle_plane->push_back(found);
  }
  return planes;
}

CloudView RenderedFrame::view() const
{
  CloudView v;
  v.data = reinterpret_cast<const uint8_t*>(xyz.data());
  v.width = width;
  v.height = height;
  v.point_step = 3 * sizeof(float);
  v.row_step = v.point_step * width;
  return v;
}

double kinectNoiseSigma(double depth, double coefficient)
{
  return structuredLightSigma(depth, coefficient);
}

SceneRenderer::SceneRenderer(const Scene& scene, const CameraIntrinsics& intrinsics)
  : scene_(scene), intrinsics_(intrinsics)
{
  true_planes_ = scene_.truePlanes(&rectangle_plane_);
}

namespace
{
// Unit-variance noise field: a Gaussian-smoothed white field (separable, renormalized) mixed
// with an independent share of the variance.
std::vector<float> correlatedField(int width, int height, const KinectNoise& noise, uint32_t seed)
{
  std::mt19937 rng(seed ^ 0x9e3779b9u);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  const int radius = static_cast<int>(std::ceil(3.0 * noise.correlation_px));
  // White noise with a margin of the kernel's radius, so the image's border is smoothed as its middle.
  const int padded_width = width + 2 * radius, padded_height = height + 2 * radius;
  std::vector<float> white(static_cast<size_t>(padded_width) * padded_height);
  for (float& x : white) x = gauss(rng);
  std::vector<float> kernel(2 * radius + 1);
  double squares = 0.0;
  for (int i = -radius; i <= radius; ++i)
  {
    kernel[i + radius] = static_cast<float>(std::exp(-0.5 * i * i / (noise.correlation_px * noise.correlation_px)));
    squares += kernel[i + radius] * kernel[i + radius];
  }
  // Unit sum of squares: each pass, and so both, keep a unit variance.
  for (float& w : kernel) w = static_cast<float>(w / std::sqrt(squares));
  std::vector<float> rows(static_cast<size_t>(width) * padded_height), field(static_cast<size_t>(width) * height);
  for (int v = 0; v < padded_height; ++v)
    for (int u = 0; u < width; ++u)
    {
      float sum = 0.0f;
      for (int i = 0; i <= 2 * radius; ++i) sum += kernel[i] * white[static_cast<size_t>(v) * padded_width + u + i];
      rows[static_cast<size_t>(v) * width + u] = sum;
    }
  const float correlated = static_cast<float>(std::sqrt(noise.correlated_variance));
  const float independent = static_cast<float>(std::sqrt(noise.independent_variance));
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u)
    {
      float sum = 0.0f;
      for (int i = 0; i <= 2 * radius; ++i) sum += kernel[i] * rows[static_cast<size_t>(v + i) * width + u];
      field[static_cast<size_t>(v) * width + u] = correlated * sum + independent * gauss(rng);
    }
  return field;
}
}  // namespace

RenderedFrame SceneRenderer::render(const Eigen::Isometry3d& camera_to_world, const KinectNoise& noise,
                                    uint32_t seed) const
{
  const CameraIntrinsics& k = intrinsics_;
  RenderedFrame frame;
  frame.width = k.width;
  frame.height = k.height;
  frame.camera_to_world = camera_to_world;
  frame.xyz.assign(static_cast<size_t>(k.width) * k.height * 3, kNaN);
  frame.pixel_plane.assign(static_cast<size_t>(k.width) * k.height, -1);
  frame.visible_points.assign(true_planes_.size(), 0);

  const Eigen::Matrix3d r = camera_to_world.linear();
  const Eigen::Vector3d eye = camera_to_world.translation();
  // Per rectangle, precomputed plane terms: t = (offset - n.eye) / n.dir.
  struct RectTerms
  {
    Eigen::Vector3d n;
    double n_eye_gap;
  };
  std::vector<RectTerms> terms;
  for (const auto& rect : scene_.rectangles)
  {
    const Eigen::Vector3d n = rect.axis_u.cross(rect.axis_v);
    terms.push_back(RectTerms{n, n.dot(rect.center - eye)});
  }
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double fb = k.fx * noise.baseline;
  const std::vector<float> field = noise.correlation_px > 0.0 ? correlatedField(k.width, k.height, noise, seed)
                                                              : std::vector<float>();

  for (int v = 0; v < k.height; ++v)
  {
    for (int u = 0; u < k.width; ++u)
    {
      // Camera ray with unit z, so the ray parameter t is the depth.
      const Eigen::Vector3d dir_cam((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Eigen::Vector3d dir = r * dir_cam;
      double best_t = std::numeric_limits<double>::infinity();
      int best_plane = -1;
      for (size_t i = 0; i < scene_.rectangles.size(); ++i)
      {
        const double denom = terms[i].n.dot(dir);
        if (std::abs(denom) < 1e-12) continue;
        const double t = terms[i].n_eye_gap / denom;
        if (t <= 0.0 || t >= best_t) continue;
        const SceneRectangle& rect = scene_.rectangles[i];
        const Eigen::Vector3d q = eye + t * dir - rect.center;
        if (std::abs(q.dot(rect.axis_u)) > rect.half_u || std::abs(q.dot(rect.axis_v)) > rect.half_v) continue;
        best_t = t;
        best_plane = rectangle_plane_[i];
      }
      for (const auto& cyl : scene_.cylinders)
      {
        // Vertical cylinder: solve in xy, check the height.
        const Eigen::Vector2d o(eye.x() - cyl.base.x(), eye.y() - cyl.base.y()), dd(dir.x(), dir.y());
        const double a = dd.squaredNorm(), b = 2.0 * o.dot(dd), c = o.squaredNorm() - cyl.radius * cyl.radius;
        const double disc = b * b - 4 * a * c;
        if (a < 1e-12 || disc < 0) continue;
        for (double sign : {-1.0, 1.0})
        {
          const double t = (-b + sign * std::sqrt(disc)) / (2 * a);
          const double z = eye.z() + t * dir.z();
          if (t > 0 && t < best_t && z >= cyl.base.z() && z <= cyl.base.z() + cyl.height)
          {
            best_t = t;
            best_plane = -1;
            break;
          }
        }
      }
      for (const auto& sph : scene_.spheres)
      {
        const Eigen::Vector3d o = eye - sph.center;
        const double a = dir.squaredNorm(), b = 2.0 * o.dot(dir), c = o.squaredNorm() - sph.radius * sph.radius;
        const double disc = b * b - 4 * a * c;
        if (disc < 0) continue;
        const double t = (-b - std::sqrt(disc)) / (2 * a);
        if (t > 0 && t < best_t)
        {
          best_t = t;
          best_plane = -1;
        }
      }
      if (!std::isfinite(best_t) || best_t < k.min_range || best_t > k.max_range) continue;
      const size_t pixel = static_cast<size_t>(v) * k.width + u;
      if (best_plane >= 0) ++frame.visible_points[best_plane];
      frame.pixel_plane[pixel] = best_plane;
      double depth = best_t;
      if (noise.gaussian)
        depth += kinectNoiseSigma(best_t, noise.coefficient) * (field.empty() ? gauss(rng) : field[pixel]);
      if (noise.quantize)
      {
        // Depth comes from disparity in 1/subpixel pixel steps: the step grows with depth^2.
        const double disparity = std::round(fb / depth * noise.subpixel) / noise.subpixel;
        if (disparity <= 0.0) continue;
        depth = fb / disparity;
      }
      frame.xyz[pixel * 3 + 0] = static_cast<float>(dir_cam.x() * depth);
      frame.xyz[pixel * 3 + 1] = static_cast<float>(dir_cam.y() * depth);
      frame.xyz[pixel * 3 + 2] = static_cast<float>(depth);
    }
  }
  return frame;
}

Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target)
{
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);  // down in the image
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = eye;
  return pose;
}

Scene makeOfficeRoom()
{
  Scene s;
  s.addRoom(3.0, 2.5, 2.8);
  s.addBox({1.6, 1.2, 0.375}, {0.6, 0.4, 0.375}, 0.3, "table");
  s.addBox({-2.6, -1.5, 0.6}, {0.3, 0.5, 0.6}, 0.0, "cabinet");
  s.addBox({0.5, -2.3, 0.45}, {0.8, 0.2, 0.45}, 0.0, "shelf");
  s.cylinders.push_back(SceneCylinder{{-1.2, 1.5, 0.0}, 0.25, 1.1});
  s.cylinders.push_back(SceneCylinder{{1.8, -1.0, 0.0}, 0.15, 0.9});
  s.spheres.push_back(SceneSphere{{-1.5, -0.8, 0.35}, 0.35});
  return s;
}

Scene makeRampStairsHall()
{
  Scene s;
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  s.addRectangle({0, 0, 0}, ex, ey, 4.0, 3.0, "floor");
  s.addRectangle({-4.0, 0, 1.5}, ey, ez, 3.0, 1.5, "wall_west");
  s.addRectangle({0, -3.0, 1.5}, ex, ez, 4.0, 1.5, "wall_south");
  // North wall with a door 1.0 m wide, 2.0 m high, recessed 10 cm.
  s.addRectangle({-2.25, 3.0, 1.5}, ex, ez, 1.75, 1.5, "wall_north");
  s.addRectangle({2.25, 3.0, 1.5}, ex, ez, 1.75, 1.5, "wall_north");
  s.addRectangle({0.0, 3.0, 2.5}, ex, ez, 0.5, 0.5, "wall_north");
  s.addRectangle({0.0, 3.1, 1.0}, ex, ez, 0.5, 1.0, "door");
  // Ramp rising 10 degrees along +x from (1.0, -2.5) , 2.5 m long, 1.2 m wide.
  const double slope = 10.0 * kPi / 180.0;
  const Eigen::Vector3d up_ramp(std::cos(slope), 0, std::sin(slope));
  s.addRectangle(Eigen::Vector3d(1.0, -2.2, 0.0) + 1.25 * up_ramp, up_ramp, ey, 1.25, 0.6, "ramp");
  // Stairs along the east wall: three treads 15 cm apart, each 0.3 m deep, 1.2 m wide.
  for (int i = 0; i < 3; ++i)
  {
    const double h = 0.15 * (i + 1);
    s.addBox({2.6 + 0.3 * i + 0.15, 1.2, h / 2.0}, {0.15, 0.6, h / 2.0}, 0.0, "stair" + std::to_string(i));
  }
  s.addRectangle({4.0, 0, 1.5}, ey, ez, 3.0, 1.5, "wall_east");
  s.cylinders.push_back(SceneCylinder{{-1.5, 0.8, 0.0}, 0.3, 1.2});
  s.spheres.push_back(SceneSphere{{-2.0, -1.5, 0.4}, 0.4});
  return s;
}

Scene makeClutteredLab()
{
  Scene s;
  s.addRoom(2.5, 2.0, 2.6);
  s.addBox({1.5, 1.3, 0.37}, {0.7, 0.35, 0.37}, 0.0, "desk_north");
  s.addBox({-1.2, -1.4, 0.37}, {0.5, 0.4, 0.37}, 0.5, "desk_south");
  s.addBox({-2.2, 1.2, 0.9}, {0.25, 0.45, 0.9}, 0.0, "cabinet_tall");
  s.addBox({2.2, -1.2, 0.45}, {0.25, 0.5, 0.45}, 0.0, "cabinet_low");
  s.addBox({0.4, 1.6, 0.2}, {0.25, 0.2, 0.2}, 0.2, "crate");
  // Non-planar clutter: bins, a bin on a desk, balls.
  s.cylinders.push_back(SceneCylinder{{-0.6, 1.5, 0.0}, 0.2, 0.7});
  s.cylinders.push_back(SceneCylinder{{1.6, 1.3, 0.74}, 0.1, 0.3});
  s.cylinders.push_back(SceneCylinder{{1.2, -0.9, 0.0}, 0.35, 1.8});
  s.spheres.push_back(SceneSphere{{-1.4, 0.3, 0.3}, 0.3});
  s.spheres.push_back(SceneSphere{{0.6, -1.6, 0.25}, 0.25});
  return s;
}

std::vector<Eigen::Isometry3d> roomTour(int frames, const Eigen::Vector3d& centre, double radius)
{
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < frames; ++i)
  {
    const double a = 2.0 * kPi * i / std::max(1, frames);
    const Eigen::Vector3d eye = centre + radius * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
    // Look outward and 20 degrees down so floor and walls share the view.
    const Eigen::Vector3d target = eye + Eigen::Vector3d(std::cos(a + 0.4), std::sin(a + 0.4), -0.36);
    poses.push_back(lookAt(eye, target));
  }
  return poses;
}

std::vector<Eigen::Isometry3d> wallApproach(int frames, double wall_x, double start_distance, double end_distance)
{
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < frames; ++i)
  {
    const double f = frames > 1 ? static_cast<double>(i) / (frames - 1) : 0.0;
    const double distance = start_distance + f * (end_distance - start_distance);
    const Eigen::Vector3d eye(wall_x - distance, 0.1, 1.0);
    poses.push_back(lookAt(eye, eye + Eigen::Vector3d(1.0, 0.0, -0.15)));
  }
  return poses;
}

}  // namespace hough_plane_detector
