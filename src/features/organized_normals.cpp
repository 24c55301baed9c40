#include "pcl_ddg/features/organized_normals.h"

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "pcl_ddg/features/plane_fit.h"
#include "pcl_ddg/interruption.h"
#include "vector_lanes.h"
#include "window_masks.h"
#include "window_sums.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace {

using namespace detail;  // WindowSums, and the grid bits of window_masks.h

/** One tile row's covariances side by side, as fitPlaneNormals takes them, and their planes. */
struct RowPlanes {
  std::array<double, kTile> count, xx, xy, xz, yy, yz, zz;
  std::array<double, kTile> normal_x, normal_y, normal_z, surface_variation;
  std::array<std::uint8_t, kTile> valid;

  /** The windows' covariances from their sums (WindowSums::rowSums); none under 3 points. */
  void setFromWindowSums(const double* sums, int width);
  /** Pixel j's covariance: that of points 0 .. count - 1 about their centroid, in two passes. */
  void setFromPoints(int j, const Eigen::Matrix3Xd& points, int count) {
    const Eigen::Vector3d centroid = count > 0
                                         ? Eigen::Vector3d(points.leftCols(count).rowwise().mean())
                                         : Eigen::Vector3d::Zero();
    Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3d d = points.col(i) - centroid;
      c.noalias() += d * d.transpose();
    }
    c *= count >= 3 ? 1.0 / count : 0.0;
    xx[j] = c(0, 0), xy[j] = c(0, 1), xz[j] = c(0, 2), yy[j] = c(1, 1), yz[j] = c(1, 2);
    zz[j] = c(2, 2);
  }
  void fit(int width) {
    fitPlaneNormals(width, {xx.data(), xy.data(), xz.data(), yy.data(), yz.data(), zz.data()},
                    {normal_x.data(), normal_y.data(), normal_z.data(), surface_variation.data(),
                     valid.data()});
  }
};

PCL_DDG_WIDE_LANES void RowPlanes::setFromWindowSums(const double* sums, int width) {
  using Sums = detail::WindowSums;
  const auto channel = [sums](int c) { return sums + c * kTile; };
  const double *n = channel(Sums::kCount), *x = channel(Sums::kX), *y = channel(Sums::kY),
               *z = channel(Sums::kZ);
  const double *sxx = channel(Sums::kXX), *sxy = channel(Sums::kXY), *sxz = channel(Sums::kXZ),
               *syy = channel(Sums::kYY), *syz = channel(Sums::kYZ), *szz = channel(Sums::kZZ);
#pragma omp simd
  for (int j = 0; j < width; ++j) {
    count[j] = n[j];
    const double inverse = n[j] >= 3.0 ? 1.0 / n[j] : 0.0;
    const double mx = x[j] * inverse, my = y[j] * inverse, mz = z[j] * inverse;
    xx[j] = sxx[j] * inverse - mx * mx, xy[j] = sxy[j] * inverse - mx * my;
    xz[j] = sxz[j] * inverse - mx * mz, yy[j] = syy[j] * inverse - my * my;
    yz[j] = syz[j] * inverse - my * mz, zz[j] = szz[j] * inverse - mz * mz;
  }
}

void setNaN(pcl::Normal& n) {
  n.normal_x = n.normal_y = n.normal_z = n.curvature = std::numeric_limits<float>::quiet_NaN();
}

}  // namespace

OrganizedNormalResult computeOrganizedPCANormals(
    const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud, const OrganizedNormalOptions& options) {
  if (options.window_radius < 1) {
    throw pcl::BadArgumentException("the window radius must be >= 1 pixel");
  }
  auto search = std::make_shared<OrganizedGridSearch<pcl::PointXYZ>>(options.max_depth_jump);
  search->setInputCloud(cloud);  // throws unless organized
  const Eigen::Matrix3Xd* positions = options.positions.get();
  if (positions && positions->cols() != static_cast<Eigen::Index>(cloud->size()))
    throw pcl::BadArgumentException("the positions must have a column per pixel");
  // In double: the exact coordinates when given, else the floats.
  const auto position = [&](int pixel) -> Eigen::Vector3d {
    if (positions) return positions->col(pixel);
    return (*cloud)[pixel].getVector3fMap().cast<double>();
  };
  const Image image{static_cast<int>(cloud->width), static_cast<int>(cloud->height)};
  const int w = options.window_radius;
  const Eigen::Vector3d origin = cloud->sensor_origin_.head<3>().cast<double>();
  const Eigen::Vector3d viewpoint = options.viewpoint.value_or(origin);

#ifdef _OPENMP
  const int threads =
      options.threads > 0 ? static_cast<int>(options.threads) : omp_get_max_threads();
#else
  const int threads = 1;
#endif
  std::vector<std::uint8_t> finite(cloud->size());
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::size_t i = 0; i < cloud->size(); ++i) finite[i] = pcl::isXYZFinite((*cloud)[i]);
  const GridBits bits = gridBits(*search, image, finite, threads);

  OrganizedNormalResult result;
  result.normals.resize(cloud->size());
  result.normals.width = cloud->width;
  result.normals.height = cloud->height;
  result.normals.is_dense = false;
  result.normals.header = cloud->header;
  const int tiles_x = (image.width + kTile - 1) / kTile;
  const int tiles_y = (image.height + kTile - 1) / kTile;
  const std::uint64_t flood_shape = windowShape(w);
  std::int64_t failed = 0, window_points = 0, jump_points = 0;
  detail::InterruptionPoll interruption;
#pragma omp parallel reduction(+ : failed, window_points, jump_points) num_threads(threads)
  {
    detail::WindowSums sums(*cloud, positions, finite, w);
    RowPlanes row;
    WindowColumns columns(bits, image.height);
    pcl::Indices neighbours;
    std::vector<float> distances;
    Eigen::Matrix3Xd points(3, (2 * w + 1) * (2 * w + 1));
#pragma omp for schedule(dynamic, 1)
    for (int tile = 0; tile < tiles_x * tiles_y; ++tile) {
      if (interruption.stopped()) continue;
      const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
      const int x1 = std::min(image.width, x0 + kTile), y1 = std::min(image.height, y0 + kTile);
      const int tile_width = x1 - x0;
      const std::uint64_t in_tile =
          tile_width == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << tile_width) - 1;
      sums.startTile(x0, y0, x1, y1);
      for (int y = y0; y < y1; ++y) {
        row.setFromWindowSums(sums.rowSums(y), tile_width);
        // A window's sums hold exactly the query's neighbours when nothing in the window can
        // cut it (the common case), or when the search reaches every point of the window (a
        // bit-mask flood fill up to 7 x 7, else the search itself). Otherwise the pixel's
        // covariance is that of the points it reaches, relative to it.
        const std::uint64_t touched =
            w < 64 ? windowsTouching(bits.blocking, x0, y, w, image.height) : ~std::uint64_t{0};
        std::uint64_t cut = 0;
        for (std::uint64_t check = touched & in_tile; check != 0; check &= check - 1) {
          const int j = __builtin_ctzll(check), x = x0 + j, pixel = image.index(x, y);
          if (!finite[pixel]) continue;
          int count = 0;
          const Eigen::Vector3d query = position(pixel);
          if (w <= kMaskRadius) {
            columns.moveTo(x0, y);
            const WindowMasks masks = floodWindow(columns, j, flood_shape);
            if (masks.reached == masks.points) continue;
            for (std::uint64_t reached = masks.reached; reached != 0; reached &= reached - 1) {
              const int bit = __builtin_ctzll(reached);
              const int neighbour =
                  image.index(x - kMaskRadius + bit % 8, y - kMaskRadius + bit / 8);
              points.col(count++) = position(neighbour) - query;
            }
          } else {
            const int x_begin = std::max(0, x - w), y_begin = std::max(0, y - w);
            const int x_end = std::min(image.width, x + w + 1);
            const int y_end = std::min(image.height, y + w + 1);
            if (!anyInWindow(bits.blocking, x_begin, y_begin, x_end, y_end)) continue;
            if (search->windowReach(pixel, w) == static_cast<int>(std::lround(row.count[j])))
              continue;
            count = search->windowSearch(pixel, w, neighbours, distances);
            for (int i = 0; i < count; ++i) {
              points.col(i) = position(neighbours[i]) - query;
            }
          }
          row.setFromPoints(j, points, count);
          cut |= std::uint64_t{1} << j;
        }
        row.fit(tile_width);
        for (int j = 0; j < tile_width; ++j) {
          const int pixel = image.index(x0 + j, y);
          pcl::Normal& out = result.normals[pixel];
          if (!finite[pixel]) {
            setNaN(out);
            continue;
          }
          ++((cut >> j) & 1u ? jump_points : window_points);
          if (!row.valid[j]) {
            setNaN(out);
            ++failed;
            continue;
          }
          const double nx = row.normal_x[j], ny = row.normal_y[j], nz = row.normal_z[j];
          const double towards = Eigen::Vector3d(nx, ny, nz).dot(viewpoint - position(pixel));
          const double sign = towards < 0.0 ? -1.0 : 1.0;
          out.normal_x = static_cast<float>(sign * nx);
          out.normal_y = static_cast<float>(sign * ny);
          out.normal_z = static_cast<float>(sign * nz);
          out.curvature = static_cast<float>(row.surface_variation[j]);
        }
      }
    }
  }
  interruption.throwIfStopped();
  result.failed_points = failed;
  result.window_points = window_points;
  result.jump_points = jump_points;
  result.grid = std::move(search);
  return result;
}

}  // namespace pcl_ddg
