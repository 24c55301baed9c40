#include "range_images.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace pcl_ddg {
namespace test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Hit {
  double t = kNaN;  ///< distance along the unit ray
  Eigen::Vector3d normal = Eigen::Vector3d::Constant(kNaN);
  int surface = -1;
};

Hit hitPlane(const Eigen::Vector3d& ray, const Eigen::Vector3d& point, Eigen::Vector3d normal,
             int surface) {
  normal.normalize();
  const double denominator = normal.dot(ray);
  Hit hit;
  if (std::abs(denominator) < 1e-12) return hit;
  const double t = normal.dot(point) / denominator;
  if (!(t > 0.0)) return hit;
  hit.t = t;
  hit.normal = denominator > 0.0 ? -normal : normal;
  hit.surface = surface;
  return hit;
}

Hit hitSphere(const Eigen::Vector3d& ray, const Eigen::Vector3d& centre, double radius) {
  const double b = ray.dot(centre), c = centre.squaredNorm() - radius * radius;
  const double discriminant = b * b - c;
  Hit hit;
  if (discriminant < 0.0) return hit;
  hit.t = b - std::sqrt(discriminant);
  hit.normal = (hit.t * ray - centre).normalized();
  hit.surface = 0;
  return hit;
}

Hit hitCylinder(const Eigen::Vector3d& ray, const Eigen::Vector3d& centre, double radius) {
  // Axis along y: intersect in the xz plane.
  const Eigen::Vector2d d(ray.x(), ray.z()), c(centre.x(), centre.z());
  const double a = d.squaredNorm(), b = d.dot(c), k = c.squaredNorm() - radius * radius;
  const double discriminant = b * b - a * k;
  Hit hit;
  if (discriminant < 0.0) return hit;
  hit.t = (b - std::sqrt(discriminant)) / a;
  const Eigen::Vector3d p = hit.t * ray;
  hit.normal = Eigen::Vector3d(p.x() - centre.x(), 0.0, p.z() - centre.z()).normalized();
  hit.surface = 0;
  return hit;
}

Hit trace(RangeScene scene, const Eigen::Vector3d& ray) {
  switch (scene) {
    case RangeScene::Plane:
      return hitPlane(ray, {0.0, 0.0, 2.0}, {0.3, -0.2, -1.0}, 0);
    case RangeScene::Sphere:
      return hitSphere(ray, {0.0, 0.0, 2.5}, 1.0);
    case RangeScene::Cylinder:
      return hitCylinder(ray, {0.0, 0.0, 2.5}, 0.8);
    case RangeScene::BoxOnWall: {
      const Hit front = hitPlane(ray, {0.0, 0.0, 2.85}, {0.0, 0.0, -1.0}, 1);
      const Eigen::Vector3d p = front.t * ray;
      if (std::abs(p.x()) < 0.4 && std::abs(p.y()) < 0.3) return front;
      return hitPlane(ray, {0.0, 0.0, 3.0}, {0.1, 0.05, -1.0}, 0);
    }
  }
  return {};
}

}  // namespace

PinholeCamera PinholeCamera::scaled(double factor) const {
  PinholeCamera c;
  c.width = static_cast<int>(std::lround(width * factor));
  c.height = static_cast<int>(std::lround(height * factor));
  c.focal = focal * factor;
  return c;
}

RangeImage renderRangeImage(RangeScene scene, const PinholeCamera& camera, double relative_noise,
                            unsigned seed, const Eigen::Vector3d& offset) {
  std::mt19937 random(seed);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  RangeImage image;
  image.cloud.reset(new pcl::PointCloud<pcl::PointXYZ>(camera.width, camera.height));
  image.cloud->is_dense = false;
  image.cloud->sensor_origin_ =
      Eigen::Vector4f(static_cast<float>(offset.x()), static_cast<float>(offset.y()),
                      static_cast<float>(offset.z()), 0.0f);
  image.normals.resize(image.cloud->size());
  std::vector<int> surface(image.cloud->size(), -1);
  const double cx = 0.5 * (camera.width - 1), cy = 0.5 * (camera.height - 1);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * camera.width + u;
      const Eigen::Vector3d ray =
          Eigen::Vector3d((u - cx) / camera.focal, (v - cy) / camera.focal, 1.0).normalized();
      const Hit hit = trace(scene, ray);
      pcl::PointXYZ& p = (*image.cloud)[i];
      image.normals[i] = hit.normal;
      surface[i] = hit.surface;
      if (!std::isfinite(hit.t)) {
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const double t = hit.t * (1.0 + relative_noise * gaussian(random));
      const Eigen::Vector3d point = t * ray + offset;
      p.x = static_cast<float>(point.x());
      p.y = static_cast<float>(point.y());
      p.z = static_cast<float>(point.z());
    }
  }
  // Chebyshev distance in pixels to the nearest pixel of another surface (small search: the
  // tests ask about the first few pixels only).
  constexpr int kReach = 8;
  image.pixels_from_step.assign(image.cloud->size(), kReach + 1);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * camera.width + u;
      for (int dv = -kReach; dv <= kReach; ++dv) {
        for (int du = -kReach; du <= kReach; ++du) {
          const int x = u + du, y = v + dv;
          if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) continue;
          const int other = surface[static_cast<std::size_t>(y) * camera.width + x];
          if (other >= 0 && surface[i] >= 0 && other != surface[i]) {
            image.pixels_from_step[i] =
                std::min(image.pixels_from_step[i], std::max(std::abs(du), std::abs(dv)));
          }
        }
      }
    }
  }
  return image;
}

WindowReachOracle::WindowReachOracle(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                     double max_depth_jump)
    : width_(static_cast<int>(cloud.width)),
      height_(static_cast<int>(cloud.height)),
      max_depth_jump_(max_depth_jump),
      range_(cloud.size(), kNaN) {
  const Eigen::Vector3d origin = cloud.sensor_origin_.head<3>().cast<double>();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const pcl::PointXYZ& p = cloud[i];
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
      range_[i] = (Eigen::Vector3d(p.x, p.y, p.z) - origin).norm();
  }
}

std::vector<int> WindowReachOracle::reach(int index, int radius, bool* ambiguous) const {
  std::vector<int> reached;
  if (!std::isfinite(range_[index])) return reached;
  const int u0 = index % width_, v0 = index / width_, side = 2 * radius + 1;
  std::vector<char> seen(static_cast<std::size_t>(side) * side, 0);
  std::vector<int> stack = {index};
  seen[static_cast<std::size_t>(radius) * side + radius] = 1;
  while (!stack.empty()) {
    const int pixel = stack.back();
    stack.pop_back();
    reached.push_back(pixel);
    const int u = pixel % width_, v = pixel / width_;
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        const int nu = u + du, nv = v + dv;
        if ((du == 0 && dv == 0) || nu < 0 || nv < 0 || nu >= width_ || nv >= height_) continue;
        if (std::abs(nu - u0) > radius || std::abs(nv - v0) > radius) continue;
        char& mark = seen[static_cast<std::size_t>(nv - v0 + radius) * side + (nu - u0 + radius)];
        if (mark) continue;
        const double a = range_[pixel], b = range_[nv * width_ + nu];
        if (!std::isfinite(b)) continue;
        const double jump = std::abs(a - b), limit = max_depth_jump_ * std::min(a, b);
        if (ambiguous && std::abs(jump - limit) <= 1e-6 * std::min(a, b)) *ambiguous = true;
        if (jump > limit) continue;
        mark = 1;
        stack.push_back(nv * width_ + nu);
      }
    }
  }
  std::sort(reached.begin(), reached.end());
  return reached;
}

}  // namespace test
}  // namespace pcl_ddg
