#include "window_sums.h"

#include <algorithm>

#include "vector_lanes.h"

namespace pcl_ddg {
namespace detail {
namespace {

/** out[j] = in[j] + in[j + step] + ... + in[j + (kTerms - 1) step] for j < count: with the number
 *  of terms known to the compiler, the sums stay in the vector lanes. */
template <int kTerms>
inline void sumTerms(const double* in, int step, int count, double* out) {
#pragma omp simd
  for (int j = 0; j < count; ++j) {
    double sum = in[j];
    for (int t = 1; t < kTerms; ++t) sum += in[j + t * step];
    out[j] = sum;
  }
}

PCL_DDG_WIDE_LANES void sumTerms(int terms, const double* in, int step, int count, double* out) {
  switch (terms) {
    case 3:
      return sumTerms<3>(in, step, count, out);
    case 5:
      return sumTerms<5>(in, step, count, out);
    case 7:
      return sumTerms<7>(in, step, count, out);
    case 9:
      return sumTerms<9>(in, step, count, out);
    case 11:
      return sumTerms<11>(in, step, count, out);
    default:
      std::copy_n(in, count, out);
      for (int t = 1; t < terms; ++t)
        for (int j = 0; j < count; ++j) out[j] += in[j + t * step];
  }
}

}  // namespace

WindowSums::WindowSums(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                       const Eigen::Matrix3Xd* positions, const std::vector<std::uint8_t>& finite,
                       int radius)
    : cloud_(cloud),
      positions_(positions),
      finite_(finite),
      width_(static_cast<int>(cloud.width)),
      height_(static_cast<int>(cloud.height)),
      radius_(radius),
      values_(static_cast<std::size_t>(kChannels) * (kTileWidth + 2 * radius)),
      ring_(static_cast<std::size_t>(2 * radius + 1) * kChannels * kTileWidth),
      sums_(static_cast<std::size_t>(kChannels) * kTileWidth) {}

void WindowSums::startTile(int x0, int y0, int x1, int y1) {
  x0_ = x0;
  tile_width_ = x1 - x0;
  const int rx0 = std::max(0, x0 - radius_), rx1 = std::min(width_, x1 + radius_);
  const int ry0 = std::max(0, y0 - radius_), ry1 = std::min(height_, y1 + radius_);
  centre_.setZero();
  int points = 0;
  for (int v = ry0; v < ry1; ++v) {
    for (int u = rx0; u < rx1; ++u) {
      const std::size_t pixel = static_cast<std::size_t>(v) * width_ + u;
      if (!finite_[pixel]) continue;
      centre_ += position(pixel);
      ++points;
    }
  }
  if (points > 0) centre_ /= points;
  next_row_ = y0 - radius_;
}

void WindowSums::sumAcross(int v) {
  const int span = tile_width_ + 2 * radius_, stride = kTileWidth + 2 * radius_;
  for (int k = 0; k < span; ++k) {
    const int u = x0_ - radius_ + k;
    const std::size_t pixel = static_cast<std::size_t>(v) * width_ + u;
    double* value = &values_[k];
    if (u < 0 || u >= width_ || !finite_[pixel]) {
      for (int c = 0; c < kChannels; ++c) value[c * stride] = 0.0;
      continue;
    }
    const Eigen::Vector3d d = position(pixel) - centre_;
    value[kCount * stride] = 1.0;
    value[kX * stride] = d.x(), value[kY * stride] = d.y(), value[kZ * stride] = d.z();
    value[kXX * stride] = d.x() * d.x(), value[kXY * stride] = d.x() * d.y();
    value[kXZ * stride] = d.x() * d.z(), value[kYY * stride] = d.y() * d.y();
    value[kYZ * stride] = d.y() * d.z(), value[kZZ * stride] = d.z() * d.z();
  }
  const int window = 2 * radius_ + 1;
  double* across = &ring_[static_cast<std::size_t>(v % window) * kChannels * kTileWidth];
  for (int c = 0; c < kChannels; ++c) {
    sumTerms(window, &values_[static_cast<std::size_t>(c) * stride], 1, tile_width_,
             across + c * kTileWidth);
  }
}

const double* WindowSums::rowSums(int y) {
  // The ring's slots hold rows y - w .. y + w, rows outside the image as zeros.
  const int window = 2 * radius_ + 1;
  for (; next_row_ <= y + radius_; ++next_row_) {
    if (next_row_ >= 0 && next_row_ < height_) {
      sumAcross(next_row_);
    } else {
      const std::size_t slot = static_cast<std::size_t>((next_row_ % window + window) % window);
      std::fill_n(&ring_[slot * kChannels * kTileWidth], kChannels * kTileWidth, 0.0);
    }
  }
  for (int c = 0; c < kChannels; ++c) {
    sumTerms(window, &ring_[static_cast<std::size_t>(c) * kTileWidth], kChannels * kTileWidth,
             tile_width_, &sums_[static_cast<std::size_t>(c) * kTileWidth]);
  }
  return sums_.data();
}

}  // namespace detail
}  // namespace pcl_ddg
