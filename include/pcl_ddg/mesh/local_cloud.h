#pragma once
/** \file
 * A cloud as the fits take it when its coordinates arrive as doubles (LAS X * scale + offset,
 * double PLY/PCD/VTK fields, text formats, float64 arrays): placed about a local origin chosen in
 * double, so that survey coordinates millions of units from the origin are never rounded to float
 * before they are centred.
 *
 * The rule, the same for a whole cloud, a tile and a piece: on each axis, with P the smallest
 * power of two not below the side of the bounding box of the whole input's finite points along
 * it, the origin is the box's centre rounded to a multiple of P, or 0 where the box comes within
 * P of 0 (data around the origin stays where it is). Two things follow:
 * - x - o is exact in double for every coordinate x of the box (where o != 0, |x| >= P while
 *   |x - o| <= P and o is a multiple of P), so the positions relative to o are the input's own
 *   values, and every difference the fits form is the one of the input's coordinates;
 * - |x - o| < 2 P < 4 times the box's side along that axis: the float points the searches look
 *   in (PCL's kd-tree, the pixel grid) round by at most about 2.4e-7 of the data's extent along
 *   each axis (geographic longitudes and latitudes beside heights in metres included), not of its
 *   distance from the origin.
 * Normals and curvatures do not depend on where the data sits: a cloud moved by any vector gives
 * the same results, to the last bit wherever the k-th neighbour is not tied with the next (the
 * float distances the search compares may round differently).
 */
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "pcl_ddg/mesh/positions_ref.h"

namespace pcl_ddg {

/** A world coordinate along an axis of the local frame whose origin is origin: x - origin, exact
 *  for every coordinate of the box the origin was chosen for (the rule above); on an axis whose
 *  origin is 0, x itself, not moved (-0 - -0 is +0, and worldCoordinate's -0 + 0 would be too). */
inline double localCoordinate(double world, double origin) {
  return origin == 0.0 ? world : world - origin;
}

/** localCoordinate's inverse, exact where it is. */
inline double worldCoordinate(double local, double origin) {
  return origin == 0.0 ? local : local + origin;
}

/** Whether a float holds a local coordinate exactly (then the fits may read the float points);
 *  not beyond float's range (nor NaN), where the conversion is undefined. */
inline bool floatHolds(double local) {
  return std::abs(local) <= std::numeric_limits<float>::max() &&
         double{static_cast<float>(local)} == local;
}

/** The local origin of positions (3 x N, world coordinates) by the rule above; zero when none is
 *  finite. NaN and infinite columns are ignored. */
Eigen::Vector3d localOrigin(const PositionsRef& positions);

/** The local origin of the points within bounds (their finite points' bounding box, world
 *  coordinates, as a pass over a file finds it); zero for an empty box. */
Eigen::Vector3d localOrigin(const Eigen::AlignedBox3d& bounds);

/** A cloud relative to its local origin: float points for the searches, and the same points in
 *  double, relative to the same origin, for the fits. A point is left out where its coordinates
 *  are NaN, in both (the searches skip its float, the fits its double). */
struct LocalCloud {
  LocalCloud() = default;
  /** A float cloud as it is (origin 0, the fits read its floats): a PCL user's cloud. */
  LocalCloud(pcl::PointCloud<pcl::PointXYZ>::ConstPtr cloud)  // NOLINT: implicit on purpose
      : points(std::move(cloud)) {}
  LocalCloud(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud)  // NOLINT: implicit on purpose
      : points(cloud) {}

  pcl::PointCloud<pcl::PointXYZ>::ConstPtr points;  ///< positions as float (NaN kept)
  /** World coordinates minus origin, column i for point i; null: the floats are exact. */
  std::shared_ptr<Eigen::Matrix3Xd> positions;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< in world coordinates
};

/** positions (world coordinates) relative to origin, and their float points (NaN kept; is_dense
 *  when all are finite), organized width points per row when width > 0 (it must divide their
 *  number). The doubles are kept only where the floats do not hold them exactly (a float file's
 *  coordinates near the origin need none). The points' sensor_origin_ is the world origin in the
 *  local frame (PCL's default sensor; organized clouds measure their ranges from it). */
LocalCloud makeLocalCloud(const PositionsRef& positions, const Eigen::Vector3d& origin,
                          std::uint32_t width = 0);

/** The same from positions already relative to origin (world coordinates minus origin), taken
 *  as they are and not copied: they become the LocalCloud's positions, or none when the floats
 *  hold them exactly (then the caller's matrix is left to the caller alone). What lets a caller
 *  shift its own coordinates in place and back (x - origin is exact, by the rule above, and so
 *  is adding origin back) instead of keeping a second copy. */
LocalCloud localCloudOf(std::shared_ptr<Eigen::Matrix3Xd> relative, const Eigen::Vector3d& origin,
                        std::uint32_t width = 0);

/** The same from float coordinates where they lie (a float file's rows: x, y, z at byte offsets
 *  offsets[0..2] of each of count rows of stride bytes, world coordinates), without a double
 *  copy: the float points about origin when they hold every finite point's local coordinates
 *  exactly (floatHolds(localCoordinate(x, origin)): always about localOrigin of the rows, whose
 *  floats are multiples of the box's smallest ulp there), else an empty LocalCloud (points null:
 *  make it from the doubles). */
LocalCloud localCloudOfFloats(const std::uint8_t* rows, std::size_t stride,
                              const std::uint32_t offsets[3], std::size_t count,
                              const Eigen::Vector3d& origin, std::uint32_t width = 0);

/** The same about positions' own local origin. */
inline LocalCloud makeLocalCloud(const PositionsRef& positions, std::uint32_t width = 0) {
  return makeLocalCloud(positions, localOrigin(positions), width);
}

}  // namespace pcl_ddg
