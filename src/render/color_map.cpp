#include "pcl_ddg/render/color_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace pcl_ddg {
namespace {

using Rgb = std::array<double, 3>;

// Piecewise-linear interpolation through evenly spaced control colours, t in [0, 1].
template <std::size_t N>
Rgb interpolate(const std::array<Rgb, N>& stops, double t) {
  const double x = std::clamp(t, 0.0, 1.0) * (N - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), N - 2);
  const double f = x - static_cast<double>(i);
  Rgb c;
  for (int k = 0; k < 3; ++k) c[k] = (1 - f) * stops[i][k] + f * stops[i + 1][k];
  return c;
}

double percentile(std::vector<double> sorted_copy, double p) {
  const auto k = static_cast<std::size_t>(std::round(p / 100.0 * (sorted_copy.size() - 1)));
  std::nth_element(sorted_copy.begin(), sorted_copy.begin() + static_cast<std::ptrdiff_t>(k),
                   sorted_copy.end());
  return sorted_copy[k];
}

}  // namespace

ColorRange colorRange(const Eigen::VectorXd& values, ColorMap map, const ColorScale& scale) {
  std::vector<double> finite;
  finite.reserve(static_cast<std::size_t>(values.size()));
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (std::isfinite(values[i])) finite.push_back(values[i]);
  }
  ColorRange range;
  if (!finite.empty()) {
    range.low = percentile(finite, scale.low_percentile);
    range.high = percentile(finite, scale.high_percentile);
  }
  if (map == ColorMap::Diverging) {
    range.high = std::max(std::abs(range.low), std::abs(range.high));
    range.low = -range.high;
  }
  return range;
}

std::array<std::uint8_t, 3> colorAt(ColorMap map, double t) {
  static const std::array<Rgb, 3> kDiverging = {{{59, 76, 192}, {240, 240, 240}, {180, 4, 38}}};
  static const std::array<Rgb, 5> kSequential = {
      {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  const Rgb c =
      map == ColorMap::Diverging ? interpolate(kDiverging, t) : interpolate(kSequential, t);
  std::array<std::uint8_t, 3> rgb;
  for (int k = 0; k < 3; ++k) rgb[k] = static_cast<std::uint8_t>(std::lround(c[k]));
  return rgb;
}

Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> colorize(const Eigen::VectorXd& values, ColorMap map,
                                                        const ColorScale& scale) {
  return colorizeWithin(values, map, colorRange(values, map, scale));
}

Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> colorizeWithin(const Eigen::VectorXd& values,
                                                              ColorMap map,
                                                              const ColorRange& limits) {
  const double lo = limits.low;
  const double range = limits.high > lo ? limits.high - lo : 1.0;
  Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> rgb(3, values.size());
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      rgb.col(i).setConstant(128);
      continue;
    }
    const std::array<std::uint8_t, 3> c = colorAt(map, (values[i] - lo) / range);
    for (int k = 0; k < 3; ++k) rgb(k, i) = c[k];
  }
  return rgb;
}

}  // namespace pcl_ddg
