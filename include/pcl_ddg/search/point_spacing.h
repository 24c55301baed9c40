#pragma once
/** \file
 * What a cloud's sampling can support, measured before fitting: the spacing of its points, the
 * quantum its coordinates are rounded to, and how many neighbours a radius holds.
 *
 * Coordinate quantum: the largest, over x, y and z, of the smallest positive difference between
 * two distinct coordinate values. A float holds 24 bits, so UTM northings (about 5e6 m) in a
 * float are multiples of 0.5 m. When the quantum exceeds half the median spacing s, the points
 * sit on a lattice coarser than the surface they sample: neighbourhoods tie exactly and plane fits
 * come out along the lattice's axes. `quantised()` says so.
 *
 * Spacing: the median distance from a point to its nearest distinct neighbour (exact duplicates
 * skipped), over up to `samples` points taken at a regular stride.
 *
 * Radius statistics: for a ball of radius r, the number of points it holds around each sampled
 * point (the point itself included, as PCL counts), and the radius that would give 90 % of the
 * sampled points at least `min_neighbours`: the 90th percentile of the distance to their
 * min_neighbours-th nearest point.
 */
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <array>
#include <cstdint>
#include <vector>

namespace pcl_ddg {

struct PointSpacing {
  double quantum = 0.0;         ///< coordinate quantum (0: fewer than two distinct values)
  double median_spacing = 0.0;  ///< s (0: fewer than two distinct points)
  /** The quantum exceeds half the spacing. */
  bool quantised() const { return median_spacing > 0.0 && quantum > 0.5 * median_spacing; }
};

/** Over the finite points; a kd-tree is built only when the quantum is at least 1e-5 of the
 *  bounding box's diagonal (CoordinateSpread::spacingMatters; spacing 0 otherwise). */
PointSpacing measurePointSpacing(const pcl::PointCloud<pcl::PointXYZ>& cloud, int samples = 10000);

/** A cloud's quantum and the diagonal of its bounding box. */
struct CoordinateSpread {
  double quantum = 0.0;
  double diagonal = 0.0;
  /** Whether the spacing can reach half the quantum: below 1e-5 of the diagonal no real scan's
   *  spacing does, and its kd-tree is not worth building. */
  bool spacingMatters() const { return quantum >= 1e-5 * diagonal; }
};

/** The finite points' values along x, y and z, gathered a point at a time (a file read in
 *  pieces: pcl_ddg_info), kept as unsigned keys in the floats' order, 12 bytes a point. */
class CoordinateValues {
 public:
  void reserve(std::size_t points);
  /** Non-finite points are left out. */
  void add(const float* xyz);
  std::size_t size() const { return keys_[0].size(); }
  /** Of the values added; sorts them in place. */
  CoordinateSpread spread();

 private:
  std::array<std::vector<std::uint32_t>, 3> keys_;
};

/** The median distance from a point to its nearest distinct neighbour, over the points
 *  xyz[3 i .. 3 i + 2] (finite) taken at a regular stride of n / samples, at least 1 (at most
 *  2 x `samples` of them); 0 for fewer than two distinct points. */
double medianSpacing(const std::vector<float>& xyz, int samples = 10000);

struct RadiusNeighbourCounts {
  std::int64_t sampled = 0;
  std::int64_t min = 0, median = 0;
  double share_under_3 = 0.0;            ///< of the sampled points, fewer than 3 in the ball
  double radius_for_min_neighbours = 0;  ///< 90 % of the sampled points get min_neighbours
};

/** Throws pcl::BadArgumentException unless radius > 0 and min_neighbours >= 1. */
RadiusNeighbourCounts countRadiusNeighbours(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                            double radius, int min_neighbours, int samples = 10000);

}  // namespace pcl_ddg
