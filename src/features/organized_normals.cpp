#include "pcl_ddg/features/organized_normals.h"

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "pcl_ddg/features/plane_fit.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace {

constexpr int kTile = 32;
// Per cell of a summed-area table: count, x, y, z, xx, xy, xz, yy, yz, zz.
constexpr int kChannels = 10;

struct Image {
  int width, height;
  int index(int x, int y) const { return y * width + x; }
};

/** Summed-area tables over the pixels: of those without a point, and of those with a depth jump
 *  to an adjacent point. A window free of both is whole; one with holes but no jump is whole
 *  unless its holes cut it. */
struct BlockingTables {
  std::vector<int> holes, jumps;
  int width;
  int count(const std::vector<int>& table, int x0, int y0, int x1, int y1) const {
    const auto at = [&](int x, int y) {
      return table[static_cast<std::size_t>(y) * (width + 1) + x];
    };
    return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);  // [x0, x1) x [y0, y1)
  }
};

BlockingTables blockingTables(const OrganizedGridSearch<pcl::PointXYZ>& search, const Image& image,
                              const std::vector<std::uint8_t>& finite) {
  BlockingTables t;
  t.width = image.width;
  t.holes.assign(static_cast<std::size_t>(image.width + 1) * (image.height + 1), 0);
  t.jumps = t.holes;
  for (int y = 0; y < image.height; ++y) {
    int holes = 0, jumps = 0;
    for (int x = 0; x < image.width; ++x) {
      const int pixel = image.index(x, y);
      std::uint8_t adjacent_points = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, v = y + dy;
          if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= image.width || v >= image.height)
            continue;
          if (finite[image.index(u, v)])
            adjacent_points |= static_cast<std::uint8_t>(
                1u << OrganizedGridSearch<pcl::PointXYZ>::stepBit(dx, dy));
        }
      }
      holes += !finite[pixel];
      jumps += finite[pixel] && search.allowedSteps(pixel) != adjacent_points;
      const std::size_t cell = static_cast<std::size_t>(y + 1) * (image.width + 1) + x + 1;
      t.holes[cell] = t.holes[cell - image.width - 1] + holes;
      t.jumps[cell] = t.jumps[cell - image.width - 1] + jumps;
    }
  }
  return t;
}

/** Whether every point of the window [x0, x1) x [y0, y1) (at most 7 x 7) is reached from its
 *  pixel (x, y) by the grid's steps inside the window: windowSearch's answer, by a flood fill on
 *  bit masks, 8 bits a row, so that the eighth column (never a pixel) absorbs the shifts'
 *  wrap-around. Steps are symmetric, so each of the four forward directions serves both ways. */
bool windowConnected(const OrganizedGridSearch<pcl::PointXYZ>& search,
                     const std::vector<std::uint8_t>& finite, const Image& image, int x, int y,
                     int x0, int y0, int x1, int y1) {
  using Search = OrganizedGridSearch<pcl::PointXYZ>;
  // Forward steps and their shifts: right, down-left, down, down-right.
  constexpr int kShift[4] = {1, 7, 8, 9};
  const int bit[4] = {Search::stepBit(1, 0), Search::stepBit(-1, 1), Search::stepBit(0, 1),
                      Search::stepBit(1, 1)};
  std::uint64_t points = 0, step[4] = {0, 0, 0, 0};
  for (int v = y0; v < y1; ++v) {
    for (int u = x0; u < x1; ++u) {
      const int pixel = image.index(u, v);
      if (!finite[pixel]) continue;
      const std::uint64_t here = std::uint64_t{1} << ((v - y0) * 8 + (u - x0));
      points |= here;
      const std::uint8_t allowed = search.allowedSteps(pixel);
      for (int d = 0; d < 4; ++d)
        if (allowed & (1u << bit[d])) step[d] |= here;
    }
  }
  std::uint64_t reached = std::uint64_t{1} << ((y - y0) * 8 + (x - x0));
  for (;;) {
    std::uint64_t grown = reached;
    for (int d = 0; d < 4; ++d) {
      grown |= (reached & step[d]) << kShift[d];
      grown |= (reached & (step[d] << kShift[d])) >> kShift[d];
    }
    grown &= points;
    if (grown == reached) return reached == points;
    reached = grown;
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
  const Image image{static_cast<int>(cloud->width), static_cast<int>(cloud->height)};
  const int w = options.window_radius;
  const Eigen::Vector3d origin = cloud->sensor_origin_.head<3>().cast<double>();
  const Eigen::Vector3d viewpoint = options.viewpoint.value_or(origin);

  std::vector<std::uint8_t> finite(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) finite[i] = pcl::isXYZFinite((*cloud)[i]);
  const BlockingTables blocking = blockingTables(*search, image, finite);

  OrganizedNormalResult result;
  result.normals.resize(cloud->size());
  result.normals.width = cloud->width;
  result.normals.height = cloud->height;
  result.normals.is_dense = false;
  result.normals.header = cloud->header;
  const int tiles_x = (image.width + kTile - 1) / kTile;
  const int tiles_y = (image.height + kTile - 1) / kTile;
  std::int64_t failed = 0, window_points = 0, jump_points = 0;
#ifdef _OPENMP
  const int threads =
      options.threads > 0 ? static_cast<int>(options.threads) : omp_get_max_threads();
#endif
#pragma omp parallel reduction(+ : failed, window_points, jump_points) num_threads(threads)
  {
    std::vector<double> table;
    pcl::Indices neighbours;
    std::vector<float> distances;
    Eigen::Matrix3Xd points(3, (2 * w + 1) * (2 * w + 1));
#pragma omp for schedule(dynamic, 1)
    for (int tile = 0; tile < tiles_x * tiles_y; ++tile) {
      const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
      const int x1 = std::min(image.width, x0 + kTile), y1 = std::min(image.height, y0 + kTile);
      // The table covers the tile and the windows of its edge pixels.
      const int rx0 = std::max(0, x0 - w), ry0 = std::max(0, y0 - w);
      const int rx1 = std::min(image.width, x1 + w), ry1 = std::min(image.height, y1 + w);
      const int rw = rx1 - rx0, rh = ry1 - ry0;
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      int region_points = 0;
      for (int y = ry0; y < ry1; ++y) {
        for (int x = rx0; x < rx1; ++x) {
          if (!finite[image.index(x, y)]) continue;
          centre += (*cloud)[image.index(x, y)].getVector3fMap().cast<double>();
          ++region_points;
        }
      }
      if (region_points > 0) centre /= region_points;
      // table(x, y) = sums over the region's pixels left of x and above y.
      const int stride = rw + 1;
      table.assign(static_cast<std::size_t>(stride) * (rh + 1) * kChannels, 0.0);
      for (int y = 0; y < rh; ++y) {
        std::array<double, kChannels> row{};
        for (int x = 0; x < rw; ++x) {
          const int pixel = image.index(rx0 + x, ry0 + y);
          if (finite[pixel]) {
            const Eigen::Vector3d d = (*cloud)[pixel].getVector3fMap().cast<double>() - centre;
            const double values[kChannels] = {
                1.0,           d.x(),         d.y(),         d.z(),         d.x() * d.x(),
                d.x() * d.y(), d.x() * d.z(), d.y() * d.y(), d.y() * d.z(), d.z() * d.z()};
            for (int c = 0; c < kChannels; ++c) row[c] += values[c];
          }
          double* cell = &table[(static_cast<std::size_t>(y + 1) * stride + x + 1) * kChannels];
          const double* above = cell - static_cast<std::size_t>(stride) * kChannels;
          for (int c = 0; c < kChannels; ++c) cell[c] = above[c] + row[c];
        }
      }
      const auto at = [&](int x, int y) {
        return &table[(static_cast<std::size_t>(y - ry0) * stride + (x - rx0)) * kChannels];
      };

      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const int pixel = image.index(x, y);
          pcl::Normal& out = result.normals[pixel];
          setNaN(out);
          if (!finite[pixel]) continue;
          const int wx0 = std::max(0, x - w), wy0 = std::max(0, y - w);
          const int wx1 = std::min(image.width, x + w + 1);
          const int wy1 = std::min(image.height, y + w + 1);
          const double *a = at(wx0, wy0), *b = at(wx1, wy0), *c = at(wx0, wy1), *d = at(wx1, wy1);
          double s[kChannels];
          for (int k = 0; k < kChannels; ++k) s[k] = d[k] - b[k] - c[k] + a[k];
          // The window's sums hold exactly the query's neighbours when nothing in the window can
          // cut it (the common case), or when the search reaches every point of the window
          // (a bit-mask flood fill up to 7 x 7, else the search itself).
          const bool whole_window =
              (blocking.count(blocking.jumps, wx0, wy0, wx1, wy1) == 0 &&
               blocking.count(blocking.holes, wx0, wy0, wx1, wy1) == 0) ||
              (w <= 3 ? windowConnected(*search, finite, image, x, y, wx0, wy0, wx1, wy1)
                      : search->windowReach(pixel, w) == static_cast<int>(std::lround(s[0])));
          PlaneFit fit;
          if (whole_window) {
            ++window_points;
            if (s[0] >= 3.0) {
              const Eigen::Vector3d mean = Eigen::Vector3d(s[1], s[2], s[3]) / s[0];
              Eigen::Matrix3d covariance;
              covariance << s[4], s[5], s[6], s[5], s[7], s[8], s[6], s[8], s[9];
              covariance = covariance / s[0] - mean * mean.transpose();
              fit = fitPlane(centre + mean, covariance);
            }
          } else {
            ++jump_points;
            const int count = search->windowSearch(pixel, w, neighbours, distances);
            const Eigen::Vector3d query = (*cloud)[pixel].getVector3fMap().cast<double>();
            for (int i = 0; i < count; ++i) {
              points.col(i) = (*cloud)[neighbours[i]].getVector3fMap().cast<double>() - query;
            }
            fit = fitPlane(points, count);
            fit.centroid += query;
          }
          if (!fit.valid) {
            ++failed;
            continue;
          }
          const Eigen::Vector3d p = (*cloud)[pixel].getVector3fMap().cast<double>();
          const Eigen::Vector3d n = fit.normal.dot(viewpoint - p) < 0.0 ? -fit.normal : fit.normal;
          out.normal_x = static_cast<float>(n.x());
          out.normal_y = static_cast<float>(n.y());
          out.normal_z = static_cast<float>(n.z());
          out.curvature = static_cast<float>(fit.surface_variation);
        }
      }
    }
  }
  result.failed_points = failed;
  result.window_points = window_points;
  result.jump_points = jump_points;
  return result;
}

}  // namespace pcl_ddg
