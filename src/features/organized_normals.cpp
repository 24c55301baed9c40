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
#include "vector_lanes.h"
#include "window_sums.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace {

constexpr int kTile = detail::WindowSums::kTileWidth;  // a tile's row is one word of RowBits

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
  /** Word `index` of row y (pixels 64 index ..), 0 left of the row. */
  std::uint64_t word(int index, int y) const {
    return index < 0 ? 0 : words_[static_cast<std::size_t>(y) * words_per_row_ + index];
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
    const auto adjacentPoints = [&](int x) {
      std::uint8_t adjacent = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, v = y + dy;
          if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= image.width || v >= image.height)
            continue;
          if (finite[image.index(u, v)])
            adjacent |= static_cast<std::uint8_t>(1u << Search::stepBit(dx, dy));
        }
      }
      return adjacent;
    };
    const bool inside = y > 0 && y < image.height - 1;
    const std::uint8_t* above = inside ? &finite[image.index(0, y - 1)] : nullptr;
    const std::uint8_t* row = &finite[image.index(0, y)];
    const std::uint8_t* below = inside ? &finite[image.index(0, y + 1)] : nullptr;
    for (int x = 0; x < image.width; ++x) {
      if (!row[x]) {
        bits.blocking.set(x, y);
        continue;
      }
      bits.points.set(x, y);
      const std::uint8_t adjacent =
          !inside || x == 0 || x == image.width - 1
              ? adjacentPoints(x)
              : static_cast<std::uint8_t>(
                    above[x - 1] << Search::stepBit(-1, -1) | above[x] << Search::stepBit(0, -1) |
                    above[x + 1] << Search::stepBit(1, -1) | row[x - 1] << Search::stepBit(-1, 0) |
                    row[x + 1] << Search::stepBit(1, 0) | below[x - 1] << Search::stepBit(-1, 1) |
                    below[x] << Search::stepBit(0, 1) | below[x + 1] << Search::stepBit(1, 1));
      const std::uint8_t allowed = search.allowedSteps(image.index(x, y));
      if (allowed != adjacent) bits.blocking.set(x, y);
      for (int d = 0; d < GridBits::kForward; ++d)
        if (allowed & (1u << kForwardBit[d])) bits.steps[d].set(x, y);
    }
  }
  return bits;
}

/** Whether any pixel of the window [x0, x1) x [y0, y1), of any size, has its bit set. */
bool anyInWindow(const RowBits& bits, int x0, int y0, int x1, int y1) {
  constexpr int kRun = 57;  // RowBits::read's longest run
  for (int v = y0; v < y1; ++v)
    for (int u = x0; u < x1; u += kRun)
      if (bits.read(u, v, std::min(kRun, x1 - u)) != 0) return true;
  return false;
}

/** For the tile row starting at pixel (x0, y), x0 a multiple of 64: bit j set where the window of
 *  radius r < 64 around pixel (x0 + j, y) holds a set bit. The rows of the windows are or-ed, then
 *  spread r pixels both ways. */
std::uint64_t windowsTouching(const RowBits& bits, int x0, int y, int r, int height) {
  std::uint64_t left = 0, centre = 0, right = 0;
  const int word = x0 >> 6;
  for (int v = std::max(0, y - r); v <= std::min(height - 1, y + r); ++v) {
    left |= bits.word(word - 1, v);
    centre |= bits.word(word, v);
    right |= bits.word(word + 1, v);
  }
  std::uint64_t touched = centre;
  for (int t = 1; t <= r; ++t) {
    touched |= (centre << t) | (left >> (64 - t)) | (centre >> t) | (right << (64 - t));
  }
  return touched;
}

constexpr int kMaskRadius = 3;

/** The 7 x 7 windows around the pixels of one row of a tile as bit masks of the grid's layers
 *  (points, then the forward steps): bit 8 (v - y + 3) + (u - x + 3) for pixel (u, v) of the
 *  window around (x, y), 8 bits a row so that the eighth column (never a pixel) absorbs the
 *  wrap-around of the flood fill's shifts. Kept column by column, each column the bits of its 7
 *  rows, so that moving down a row shifts in one bit a column and a window is 7 columns or-ed. */
class WindowColumns {
 public:
  static constexpr int kLayers = 1 + GridBits::kForward;
  static constexpr int kColumns = kTile + 2 * kMaskRadius;

  WindowColumns(const GridBits& bits, int height) : bits_(bits), height_(height) {}

  /** Columns of the tile starting at pixel column x0 (a multiple of 64) for the windows of row y.
   */
  void moveTo(int x0, int y) {
    if (x0 == x0_ && y == y_) return;
    if (x0 != x0_ || y != y_ + 1) {
      for (auto& layer : columns_) layer.fill(0);
      x0_ = x0;
      for (int v = y - kMaskRadius; v < y + kMaskRadius; ++v) shiftIn(v);
    }
    shiftIn(y + kMaskRadius);
    y_ = y;
  }

  /** Layer l's mask of the window around pixel (x0 + j, y). */
  std::uint64_t window(int layer, int j) const {
    const std::uint64_t* column = &columns_[layer][j];
    std::uint64_t mask = 0;
    for (int d = 0; d < 2 * kMaskRadius + 1; ++d) mask |= column[d] << d;
    return mask;
  }

 private:
  const RowBits& layer(int l) const { return l == 0 ? bits_.points : bits_.steps[l - 1]; }

  /** Row v (zeros outside the image) becomes the windows' bottom row. */
  void shiftIn(int v) {
    const int word = x0_ >> 6;
    for (int l = 0; l < kLayers; ++l) {
      std::uint64_t left = 0, centre = 0, right = 0;
      if (v >= 0 && v < height_) {
        left = layer(l).word(word - 1, v);
        centre = layer(l).word(word, v);
        right = layer(l).word(word + 1, v);
      }
      std::uint64_t* column = columns_[l].data();
      constexpr int kBottom = 8 * 2 * kMaskRadius;
      for (int k = 0; k < kMaskRadius; ++k)
        column[k] = (column[k] >> 8) | (((left >> (64 - kMaskRadius + k)) & 1u) << kBottom);
      for (int k = 0; k < kTile; ++k) {
        std::uint64_t& c = column[kMaskRadius + k];
        c = (c >> 8) | (((centre >> k) & 1u) << kBottom);
      }
      for (int k = 0; k < kMaskRadius; ++k) {
        std::uint64_t& c = column[kMaskRadius + kTile + k];
        c = (c >> 8) | (((right >> k) & 1u) << kBottom);
      }
    }
  }

  const GridBits& bits_;
  int height_;
  int x0_ = -1, y_ = -2;
  std::array<std::array<std::uint64_t, kColumns>, kLayers> columns_{};
};

/** The points of a window of radius w <= 3 (shape: windowShape(w)) around pixel (x0 + j, y) that
 *  the grid's steps inside the window reach from it: windowSearch's answer, by a flood fill on the
 *  window's masks (WindowColumns' layout). */
struct WindowMasks {
  std::uint64_t points = 0, reached = 0;
};

/** The bits of the window of radius w <= 3 in WindowColumns' 7 x 7 layout. */
std::uint64_t windowShape(int w) {
  if (w > kMaskRadius) return 0;
  std::uint64_t shape = 0;
  for (int v = kMaskRadius - w; v <= kMaskRadius + w; ++v)
    shape |= ((std::uint64_t{1} << (2 * w + 1)) - 1) << (8 * v + kMaskRadius - w);
  return shape;
}

WindowMasks floodWindow(const WindowColumns& columns, int j, std::uint64_t shape) {
  WindowMasks masks;
  masks.points = columns.window(0, j) & shape;
  std::uint64_t step[GridBits::kForward];
  for (int d = 0; d < GridBits::kForward; ++d) step[d] = columns.window(1 + d, j);
  masks.reached = std::uint64_t{1} << (8 * kMaskRadius + kMaskRadius);
  for (;;) {
    std::uint64_t grown = masks.reached;
    for (int d = 0; d < GridBits::kForward; ++d) {
      grown |= (masks.reached & step[d]) << kForwardShift[d];
      grown |= (masks.reached & (step[d] << kForwardShift[d])) >> kForwardShift[d];
    }
    grown &= masks.points;
    if (grown == masks.reached) return masks;
    masks.reached = grown;
    if (grown == masks.points) return masks;  // all reached: one round fewer
  }
}

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
#pragma omp parallel reduction(+ : failed, window_points, jump_points) num_threads(threads)
  {
    detail::WindowSums sums(*cloud, finite, w);
    RowPlanes row;
    WindowColumns columns(bits, image.height);
    pcl::Indices neighbours;
    std::vector<float> distances;
    Eigen::Matrix3Xd points(3, (2 * w + 1) * (2 * w + 1));
#pragma omp for schedule(dynamic, 1)
    for (int tile = 0; tile < tiles_x * tiles_y; ++tile) {
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
          const Eigen::Vector3d query = (*cloud)[pixel].getVector3fMap().cast<double>();
          if (w <= kMaskRadius) {
            columns.moveTo(x0, y);
            const WindowMasks masks = floodWindow(columns, j, flood_shape);
            if (masks.reached == masks.points) continue;
            for (std::uint64_t reached = masks.reached; reached != 0; reached &= reached - 1) {
              const int bit = __builtin_ctzll(reached);
              const int neighbour =
                  image.index(x - kMaskRadius + bit % 8, y - kMaskRadius + bit / 8);
              points.col(count++) = (*cloud)[neighbour].getVector3fMap().cast<double>() - query;
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
              points.col(i) = (*cloud)[neighbours[i]].getVector3fMap().cast<double>() - query;
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
          const pcl::PointXYZ& p = (*cloud)[pixel];
          const double nx = row.normal_x[j], ny = row.normal_y[j], nz = row.normal_z[j];
          const double towards =
              nx * (viewpoint.x() - p.x) + ny * (viewpoint.y() - p.y) + nz * (viewpoint.z() - p.z);
          const double sign = towards < 0.0 ? -1.0 : 1.0;
          out.normal_x = static_cast<float>(sign * nx);
          out.normal_y = static_cast<float>(sign * ny);
          out.normal_z = static_cast<float>(sign * nz);
          out.curvature = static_cast<float>(row.surface_variation[j]);
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
