#pragma once
/** \file
 * Elementary measures of a mesh embedded by vertex positions (3 x N, double).
 */
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <limits>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"

namespace pcl_ddg {

/**
 * A triangle is degenerate (treated as zero-area) when twice its area is at most this fraction of
 * its longest squared edge, i.e. when its smallest angle is below about 1e-12 rad. Relative, so
 * the guard means the same at any scale and far from the origin.
 */
constexpr double kDegenerateTriangleTolerance = 1e-12;

/** True for a zero-area (collinear or repeated-corner) triangle, by the relative guard above, given
 *  its corners and (b - a) x (c - a), for loops that need that cross product anyway. */
inline bool isDegenerateTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& c, const Eigen::Vector3d& cross) {
  const double longest_squared =
      std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
  // Squared on both sides: no square root in the operators' innermost loop. (Edges shorter than
  // about 1e-75 underflow here; such coordinates are outside what double geometry supports.)
  const double bound = kDegenerateTriangleTolerance * longest_squared;
  return cross.squaredNorm() <= bound * bound;
}

/** True for a zero-area (collinear or repeated-corner) triangle, by the relative guard above. */
inline bool isDegenerateTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& c) {
  return isDegenerateTriangle(a, b, c, (b - a).cross(c - a));
}

/** Mean length of the unique edges whose end points are finite (0 if there are none). */
double meanEdgeLength(const MeshTopology& topology, const PositionsRef& positions);

/** Angle quality of the non-degenerate triangles (degenerate ones are counted by MeshReport). */
struct TriangleQuality {
  double min_angle_degrees = 180.0;  ///< smallest corner angle
  std::int64_t slivers = 0;          ///< triangles with a corner below kSliverAngleDegrees
};
constexpr double kSliverAngleDegrees = 1.0;

TriangleQuality triangleQuality(const MeshTopology& topology, const PositionsRef& positions);

struct BoundingBox {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d diagonal() const { return max - min; }
};

/** Box of the finite points (NaN corners if there are none). */
BoundingBox boundingBox(const PositionsRef& positions);

}  // namespace pcl_ddg
