#pragma once
// The pixel grid of an organized cloud as bit rows, and the 7 x 7 windows around the pixels of a
// tile row as bit masks: which pixels a window holds, which can cut it (no point, or a depth jump
// to an adjacent point), and, by a flood fill over the grid's allowed steps, which of its points
// OrganizedGridSearch::windowSearch would reach. computeOrganizedPCANormals uses them to tell the
// windows its running sums serve whole from those it fits point by point.
#include <pcl/point_types.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "pcl_ddg/search/organized_grid_search.h"
#include "window_sums.h"

namespace pcl_ddg {
namespace detail {

constexpr int kTile = WindowSums::kTileWidth;  // a tile's row is one word of RowBits

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

inline GridBits gridBits(const Search& search, const Image& image,
                         const std::vector<std::uint8_t>& finite, int threads) {
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
inline bool anyInWindow(const RowBits& bits, int x0, int y0, int x1, int y1) {
  constexpr int kRun = 57;  // RowBits::read's longest run
  for (int v = y0; v < y1; ++v)
    for (int u = x0; u < x1; u += kRun)
      if (bits.read(u, v, std::min(kRun, x1 - u)) != 0) return true;
  return false;
}

/** For the tile row starting at pixel (x0, y), x0 a multiple of 64: bit j set where the window of
 *  radius r < 64 around pixel (x0 + j, y) holds a set bit. The rows of the windows are or-ed, then
 *  spread r pixels both ways. */
inline std::uint64_t windowsTouching(const RowBits& bits, int x0, int y, int r, int height) {
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
inline std::uint64_t windowShape(int w) {
  if (w > kMaskRadius) return 0;
  std::uint64_t shape = 0;
  for (int v = kMaskRadius - w; v <= kMaskRadius + w; ++v)
    shape |= ((std::uint64_t{1} << (2 * w + 1)) - 1) << (8 * v + kMaskRadius - w);
  return shape;
}

inline WindowMasks floodWindow(const WindowColumns& columns, int j, std::uint64_t shape) {
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

}  // namespace detail
}  // namespace pcl_ddg
