#include "pcl_ddg/render/mesh_render.h"

#include <stb_image_write.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/atomic_file.h"

namespace pcl_ddg {
namespace {

// Camera frame: rows are screen right, screen up, towards the viewer.
Eigen::Matrix3d viewRotation(const RenderOptions& o) {
  const double deg = 3.14159265358979323846 / 180.0;
  const Eigen::Vector3d up = o.up.normalized();
  Eigen::Vector3d side = o.front - o.front.dot(up) * up;
  if (!(side.norm() > 1e-6))
    side = std::abs(up.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d front0 = (side - side.dot(up) * up).normalized();
  const Eigen::Vector3d towards_viewer =
      Eigen::AngleAxisd(o.azimuth_degrees * deg, up) *
      (std::cos(o.elevation_degrees * deg) * front0 + std::sin(o.elevation_degrees * deg) * up);
  const Eigen::Vector3d right = up.cross(towards_viewer).normalized();
  const Eigen::Vector3d screen_up = towards_viewer.cross(right);
  Eigen::Matrix3d r;
  r.row(0) = right;
  r.row(1) = screen_up;
  r.row(2) = towards_viewer;
  return r;
}

// Orthographic projection of the finite points, centred and scaled to fit the image with a margin.
struct Screen {
  Eigen::Matrix3Xd view;  ///< positions in the camera frame
  double scale = 1.0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  int width = 0, height = 0;

  Screen(const Eigen::Matrix3Xd& positions, const RenderOptions& options)
      : view(viewRotation(options) * positions), width(options.width), height(options.height) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (Eigen::Index i = 0; i < view.cols(); ++i) {
      if (!view.col(i).allFinite()) continue;
      lo = lo.cwiseMin(view.col(i));
      hi = hi.cwiseMax(view.col(i));
    }
    scale = 0.9 * std::min(width / std::max(hi.x() - lo.x(), 1e-300),
                           height / std::max(hi.y() - lo.y(), 1e-300));
    centre = 0.5 * (lo.head<2>() + hi.head<2>());
  }

  /** Pixel x, pixel y (down), depth (larger = nearer). */
  Eigen::Vector3d project(Eigen::Index i) const {
    const Eigen::Vector3d v = view.col(i);
    return {width / 2.0 + scale * (v.x() - centre.x()), height / 2.0 - scale * (v.y() - centre.y()),
            v.z()};
  }
};

const Eigen::Vector3d kLight = Eigen::Vector3d(-0.3, 0.5, 1.0).normalized();

Image blankImage(const RenderOptions& options) {
  Image image;
  image.width = options.width;
  image.height = options.height;
  image.rgb.assign(static_cast<std::size_t>(image.width) * image.height * 3, 255);
  return image;
}

}  // namespace

DefaultView defaultView(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& normals,
                        bool geographic) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Index count = 0;
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    if (positions.col(i).allFinite()) centre += positions.col(i), ++count;
  }
  DefaultView view{Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()};
  if (count == 0) return view;
  centre /= static_cast<double>(count);
  view.centre = centre;
  if (count < 3) return view;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d facing = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    if (!positions.col(i).allFinite()) continue;
    const Eigen::Vector3d d = positions.col(i) - centre;
    covariance += d * d.transpose();
    if (normals.cols() == positions.cols() && normals.col(i).allFinite()) facing += normals.col(i);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> axes(covariance);
  const Eigen::Vector3d smallest = axes.eigenvectors().col(0);
  const Eigen::Vector3d largest = axes.eigenvectors().col(2);
  const Eigen::Vector3d vertical = geographic ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  // The side the normals face; without them (or undecided) the side of +z, then of +y.
  double side = facing.dot(smallest);
  if (std::abs(side) < 1e-3 * facing.norm() || facing.norm() == 0.0) side = smallest.z();
  if (std::abs(side) < 1e-6) side = smallest.y();
  view.front = side < 0.0 ? Eigen::Vector3d(-smallest) : smallest;
  // Up: the file's vertical as seen from there (scans and models are stored upright far more
  // often than along their largest axis: a cow is longer than tall), unless the view looks within
  // 30 degrees of it; then the largest principal axis, or north on a map seen from above.
  const Eigen::Vector3d projected = vertical - vertical.dot(view.front) * view.front;
  if (projected.norm() > 0.5) {
    view.up = projected.normalized();
  } else if (geographic) {
    view.up = (Eigen::Vector3d::UnitY() - view.front.y() * view.front).normalized();
  } else {
    view.up = largest.dot(vertical) < 0.0 ? Eigen::Vector3d(-largest) : largest;
  }
  return view;
}

Eigen::AlignedBox3d finiteBounds(const Eigen::Matrix3Xd& positions) {
  Eigen::AlignedBox3d box;  // empty
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    if (positions.col(i).allFinite()) box.extend(positions.col(i));
  }
  return box;
}

bool farFromOrigin(const Eigen::Matrix3Xd& positions) {
  const Eigen::AlignedBox3d box = finiteBounds(positions);
  return !box.isEmpty() && box.center().norm() > 100.0 * box.diagonal().norm();
}

Image renderMesh(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xi& triangles,
                 const Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>& colors,
                 const RenderOptions& options) {
  Image image = blankImage(options);
  if (triangles.cols() == 0) return image;
  const Screen screen(positions, options);
  const Eigen::Matrix3Xd& view = screen.view;

  std::vector<double> depth(static_cast<std::size_t>(image.width) * image.height,
                            -std::numeric_limits<double>::infinity());
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = screen.project(triangles(k, t));
    if (!(p[0].allFinite() && p[1].allFinite() && p[2].allFinite())) continue;
    const Eigen::Vector3d normal =
        (view.col(triangles(1, t)) - view.col(triangles(0, t)))
            .cross(view.col(triangles(2, t)) - view.col(triangles(0, t)));
    if (normal.norm() == 0.0) continue;
    const double shade = 0.25 + 0.75 * std::abs(normal.normalized().dot(kLight));
    const double area = (p[1].x() - p[0].x()) * (p[2].y() - p[0].y()) -
                        (p[2].x() - p[0].x()) * (p[1].y() - p[0].y());
    if (area == 0.0) continue;
    const int x0 =
        std::max(0, static_cast<int>(std::floor(std::min({p[0].x(), p[1].x(), p[2].x()}))));
    const int x1 = std::min(image.width - 1,
                            static_cast<int>(std::ceil(std::max({p[0].x(), p[1].x(), p[2].x()}))));
    const int y0 =
        std::max(0, static_cast<int>(std::floor(std::min({p[0].y(), p[1].y(), p[2].y()}))));
    const int y1 = std::min(image.height - 1,
                            static_cast<int>(std::ceil(std::max({p[0].y(), p[1].y(), p[2].y()}))));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        double w[3];
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d& a = p[(k + 1) % 3];
          const Eigen::Vector3d& b = p[(k + 2) % 3];
          w[k] = ((b.x() - a.x()) * (py - a.y()) - (px - a.x()) * (b.y() - a.y())) / area;
        }
        if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
        const double z = w[0] * p[0].z() + w[1] * p[1].z() + w[2] * p[2].z();
        const std::size_t pixel = static_cast<std::size_t>(y) * image.width + x;
        if (z <= depth[pixel]) continue;
        depth[pixel] = z;
        for (int c = 0; c < 3; ++c) {
          double value = 0.0;
          for (int k = 0; k < 3; ++k) value += w[k] * colors(c, triangles(k, t));
          image.rgb[3 * pixel + c] =
              static_cast<std::uint8_t>(std::clamp(shade * value, 0.0, 255.0));
        }
      }
    }
  }
  return image;
}

Image renderPoints(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& normals,
                   const Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>& colors,
                   const RenderOptions& options) {
  Image image = blankImage(options);
  const Screen screen(positions, options);
  std::vector<Eigen::Index> finite;
  double z_lo = std::numeric_limits<double>::infinity(), z_hi = -z_lo;
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    if (!positions.col(i).allFinite()) continue;
    finite.push_back(i);
    z_lo = std::min(z_lo, screen.view(2, i));
    z_hi = std::max(z_hi, screen.view(2, i));
  }
  if (finite.empty()) return image;
  // Splats about as wide as the spacing of a surface sampled evenly across the picture.
  const double radius =
      options.point_radius_pixels > 0.0
          ? options.point_radius_pixels
          : std::clamp(0.75 * std::sqrt(0.3 * image.width * image.height / finite.size()), 1.0,
                       6.0);
  const Eigen::Matrix3d rotation = viewRotation(options);
  const bool shaded = normals.cols() == positions.cols();
  std::vector<double> depth(static_cast<std::size_t>(image.width) * image.height,
                            -std::numeric_limits<double>::infinity());
  for (const Eigen::Index i : finite) {
    const Eigen::Vector3d p = screen.project(i);
    // Lambert by the normal where there is one, else nearer points lighter (a depth cue).
    const Eigen::Vector3d n =
        shaded ? Eigen::Vector3d(rotation * normals.col(i)) : Eigen::Vector3d();
    const double shade = shaded && n.allFinite() && n.norm() > 0.0
                             ? 0.25 + 0.75 * std::abs(n.normalized().dot(kLight))
                             : 0.55 + 0.45 * (p.z() - z_lo) / std::max(z_hi - z_lo, 1e-300);
    const int x0 = std::max(0, static_cast<int>(std::floor(p.x() - radius)));
    const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(p.x() + radius)));
    const int y0 = std::max(0, static_cast<int>(std::floor(p.y() - radius)));
    const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(p.y() + radius)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double dx = x + 0.5 - p.x(), dy = y + 0.5 - p.y();
        if (dx * dx + dy * dy > radius * radius) continue;
        const std::size_t pixel = static_cast<std::size_t>(y) * image.width + x;
        if (p.z() <= depth[pixel]) continue;
        depth[pixel] = p.z();
        for (int c = 0; c < 3; ++c) {
          image.rgb[3 * pixel + c] =
              static_cast<std::uint8_t>(std::clamp(shade * colors(c, i), 0.0, 255.0));
        }
      }
    }
  }
  return image;
}

void savePNG(const std::string& path, const Image& image) {
  // stb encodes a 0 x 0 image into a file no reader opens: refused before the file is touched.
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
    throw FileFormatException(path + ": no PNG of a " + std::to_string(image.width) + " x " +
                              std::to_string(image.height) + " image with " +
                              std::to_string(image.rgb.size()) + " bytes");
  }
  // Encoded in memory and written by writeBytes: stb's own file writer ignores write errors.
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<std::size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.rgb.data(),
                              image.width * 3)) {
    throw FileFormatException(path + ": PNG encoding failed");
  }
  AtomicFile file(path);
  writeBytes(file.temporaryPath(), png);
  file.commit();
}

}  // namespace pcl_ddg
