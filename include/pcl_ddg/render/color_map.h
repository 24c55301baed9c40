#pragma once
/** \file
 * Scalar fields to colours, for MeshLab (per-vertex RGB) and for pictures.
 */
#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace pcl_ddg {

enum class ColorMap {
  Diverging,   ///< blue - white - red, symmetric about zero (signed curvatures)
  Sequential,  ///< dark blue - green - yellow (magnitudes, areas, errors)
};

struct ColorScale {
  /** Values are clamped at these percentiles of the finite values, so outliers do not wash out
   *  the picture. */
  double low_percentile = 2.0;
  double high_percentile = 98.0;
};

/** The values that the two ends of the colour map stand for: the scale's percentiles of the finite
 *  values, made symmetric about zero for Diverging ([0, 1] when no value is finite). */
struct ColorRange {
  double low = 0.0, high = 1.0;
};
ColorRange colorRange(const Eigen::VectorXd& values, ColorMap map, const ColorScale& scale = {});

/** The colour at t in [0, 1] along the map (clamped outside). */
std::array<std::uint8_t, 3> colorAt(ColorMap map, double t);

/** One RGB colour per value, by colorRange; NaN values are grey. */
Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> colorize(const Eigen::VectorXd& values, ColorMap map,
                                                        const ColorScale& scale = {});

/** The same within a given range (e.g. the one a colour bar shows), values beyond clamped. */
Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> colorizeWithin(const Eigen::VectorXd& values,
                                                              ColorMap map,
                                                              const ColorRange& range);

}  // namespace pcl_ddg
