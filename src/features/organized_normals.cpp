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

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace {

constexpr int kTile = 64;
// Per cell of a summed-area table: count, x, y, z, xx, xy, xz, yy, yz, zz.
constexpr int kChannels = 10;

struct Image {
  int width, height;
  int index(int x, int y) const { return y * width + x; }
};

/** One bit per pixel, each row padded with a spare word, so that any run of up to 57 bits of a
 *  row is read from two words. Rows are written by one thread each (no two share a word). */
class RowBits {
 public:
  RowBits(int width, int height)
      : words_per_row_(static_cast<std::size_t>(width) / 64 + 2),
        words_(words_per_row_ * static_cast<std::size_t>(height), 0) {}
  void set(int x, int y) { row(y)[x >> 6] |= std::uint64_t{1} << (x & 63); }
  /** Bits x .. x + count - 1 of row y, bit 0 for pixel x. */
  std::uint64_t read(int x, int y, int count) const {
    const std::uint64_t* words = &words_[static_cast<std::size_t>(y) * words_per_row_];
    const int offset = x & 63;
    std::uint64_t bits = words[x >> 6] >> offset;
    if (offset != 0) bits |= words[(x >> 6) + 1] << (64 - offset);
    return bits & ((std::uint64_t{1} << count) - 1);
  }

 private:
  std::uint64_t* row(int y) { return &words_[static_cast<std::size_t>(y) * words_per_row_]; }
  std::size_t words_per_row_;
  std::vector<std::uint64_t> words_;
};

using Search = OrganizedGridSearch<pcl::PointXYZ>;

/** The grid as bit rows: the pixels with a point; those that can cut a window (no point, or a
 *  jump to an adjacent point); and per forward step (right, down-left, down, down-right) the
 *  pixels the search may take it from. Steps are symmetric, so forward steps serve both ways. */
struct GridBits {
  static constexpr int kForward = 4;
  GridBits(int width, int height)
      : points(width, height), blocking(width, height), steps(kForward, RowBits(width, height)) {}
  RowBits points, blocking;
  std::vector<RowBits> steps;
};

constexpr int kForwardShift[GridBits::kForward] = {1, 7, 8, 9};  // in 8-bit rows of a window mask
constexpr int kForwardBit[GridBits::kForward] = {Search::stepBit(1, 0), Search::stepBit(-1, 1),
                                                 Search::stepBit(0, 1), Search::stepBit(1, 1)};

GridBits gridBits(const Search& search, const Image& image, const std::vector<std::uint8_t>& finite,
                  int threads) {
  GridBits bits(image.width, image.height);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const int pixel = image.index(x, y);
      if (!finite[pixel]) {
        bits.blocking.set(x, y);
        continue;
      }
      bits.points.set(x, y);
      std::uint8_t adjacent_points = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, v = y + dy;
          if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= image.width || v >= image.height)
            continue;
          if (finite[image.index(u, v)])
            adjacent_points |= static_cast<std::uint8_t>(1u << Search::stepBit(dx, dy));
        }
      }
      const std::uint8_t allowed = search.allowedSteps(pixel);
      if (allowed != adjacent_points) bits.blocking.set(x, y);
      for (int d = 0; d < GridBits::kForward; ++d)
        if (allowed & (1u << kForwardBit[d])) bits.steps[d].set(x, y);
    }
  }
  return bits;
}

/** A window [x0, x1) x [y0, y1) of at most 7 x 7 pixels as a bit mask, bit 8 (v - y0) + (u - x0)
 *  for pixel (u, v): 8 bits a row, so that the eighth column (never a pixel) absorbs the
 *  wrap-around of the flood fill's shifts. */
std::uint64_t windowMask(const RowBits& bits, int x0, int y0, int x1, int y1) {
  std::uint64_t mask = 0;
  for (int v = y0; v < y1; ++v) mask |= bits.read(x0, v, x1 - x0) << ((v - y0) * 8);
  return mask;
}

/** Whether any pixel of the window [x0, x1) x [y0, y1), of any size, has its bit set. */
bool anyInWindow(const RowBits& bits, int x0, int y0, int x1, int y1) {
  constexpr int kRun = 57;  // RowBits::read's longest run
  for (int v = y0; v < y1; ++v)
    for (int u = x0; u < x1; u += kRun)
      if (bits.read(u, v, std::min(kRun, x1 - u)) != 0) return true;
  return false;
}

/** The points of the window around (x, y) that the grid's steps inside the window reach from it:
 *  windowSearch's answer, by a flood fill on the window's masks. */
struct WindowMasks {
  std::uint64_t points = 0, reached = 0;
};

constexpr int kMaskRadius = 3;

WindowMasks floodWindow(const GridBits& bits, int x, int y, int x0, int y0, int x1, int y1) {
  WindowMasks masks;
  masks.points = windowMask(bits.points, x0, y0, x1, y1);
  std::uint64_t step[GridBits::kForward];
  for (int d = 0; d < GridBits::kForward; ++d) step[d] = windowMask(bits.steps[d], x0, y0, x1, y1);
  masks.reached = std::uint64_t{1} << ((y - y0) * 8 + (x - x0));
  for (;;) {
    std::uint64_t grown = masks.reached;
    for (int d = 0; d < GridBits::kForward; ++d) {
      grown |= (masks.reached & step[d]) << kForwardShift[d];
      grown |= (masks.reached & (step[d] << kForwardShift[d])) >> kForwardShift[d];
    }
    grown &= masks.points;
    if (grown == masks.reached) return masks;
    masks.reached = grown;
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
  std::int64_t failed = 0, window_points = 0, jump_points = 0;
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
          bool whole_window = !anyInWindow(bits.blocking, wx0, wy0, wx1, wy1);
          std::uint64_t reached = 0;
          if (!whole_window && w <= kMaskRadius) {
            const WindowMasks masks = floodWindow(bits, x, y, wx0, wy0, wx1, wy1);
            whole_window = masks.reached == masks.points;
            reached = masks.reached;
          } else if (!whole_window) {
            whole_window = search->windowReach(pixel, w) == static_cast<int>(std::lround(s[0]));
          }
          PlaneNormal fit;
          if (whole_window) {
            ++window_points;
            if (s[0] >= 3.0) {
              const Eigen::Vector3d mean = Eigen::Vector3d(s[1], s[2], s[3]) / s[0];
              Eigen::Matrix3d covariance;
              covariance << s[4], s[5], s[6], s[5], s[7], s[8], s[6], s[8], s[9];
              covariance = covariance / s[0] - mean * mean.transpose();
              fit = fitPlaneNormal(covariance);
            }
          } else {
            // Cut: the plane of the points the query reaches, relative to the query.
            ++jump_points;
            const Eigen::Vector3d query = (*cloud)[pixel].getVector3fMap().cast<double>();
            int count = 0;
            if (w <= kMaskRadius) {
              for (; reached != 0; reached &= reached - 1) {
                const int bit = __builtin_ctzll(reached);
                const int neighbour = image.index(wx0 + bit % 8, wy0 + bit / 8);
                points.col(count++) = (*cloud)[neighbour].getVector3fMap().cast<double>() - query;
              }
            } else {
              count = search->windowSearch(pixel, w, neighbours, distances);
              for (int i = 0; i < count; ++i) {
                points.col(i) = (*cloud)[neighbours[i]].getVector3fMap().cast<double>() - query;
              }
            }
            fit = fitPlaneNormal(points, count);
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
  result.grid = std::move(search);
  return result;
}

}  // namespace pcl_ddg
