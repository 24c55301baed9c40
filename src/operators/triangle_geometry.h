#pragma once
// Geometry of one triangle, computed where it is needed. The operators gather per vertex (each
// vertex visits its own triangles, so threads never write to shared entries) and recompute
// these few flops instead of storing per-triangle arrays: on millions of triangles memory
// traffic, not arithmetic, is the cost.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/operators/mass_matrix.h"

namespace pcl_ddg {
namespace detail {

/** Throws InvalidMeshException unless positions has one finite column per topology vertex. */
void requireMatchingPositions(const MeshTopology& topology, const Eigen::Matrix3Xd& positions);

/** Triangle t seen from its corner k: p0 is that corner, p1 and p2 follow in winding order. */
struct CornerView {
  Eigen::Vector3d p0, p1, p2;
  Eigen::Vector3d area_vector;  ///< (p1 - p0) x (p2 - p0) / 2, zero if degenerate
  double double_area = 0.0;     ///< |(p1 - p0) x (p2 - p0)|, zero if degenerate
  bool degenerate = true;

  /** Cotangent of the angle at p0, p1, p2 (index 0, 1, 2). Only for non-degenerate triangles. */
  double cotangent(int corner) const {
    const Eigen::Vector3d& o = corner == 0 ? p0 : (corner == 1 ? p1 : p2);
    const Eigen::Vector3d& a = corner == 0 ? p1 : (corner == 1 ? p2 : p0);
    const Eigen::Vector3d& b = corner == 0 ? p2 : (corner == 1 ? p0 : p1);
    return (a - o).dot(b - o) / double_area;
  }
  /** Interior angle at p0 (atan2 stays accurate for tiny and obtuse angles). */
  double angle() const { return std::atan2(double_area, (p1 - p0).dot(p2 - p0)); }
};

inline int cornerOf(const Eigen::Matrix3Xi& triangles, int t, int v) {
  return triangles(0, t) == v ? 0 : (triangles(1, t) == v ? 1 : 2);
}

inline CornerView viewFromCorner(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xi& triangles,
                                 int t, int k) {
  CornerView c;
  c.p0 = positions.col(triangles(k, t));
  c.p1 = positions.col(triangles((k + 1) % 3, t));
  c.p2 = positions.col(triangles((k + 2) % 3, t));
  if (isDegenerateTriangle(c.p0, c.p1, c.p2)) return c;
  c.area_vector = 0.5 * (c.p1 - c.p0).cross(c.p2 - c.p0);
  c.double_area = 2.0 * c.area_vector.norm();
  c.degenerate = false;
  return c;
}

/** Calls f(view, t) for every non-degenerate triangle t of v, viewed from v's corner. */
template <typename F>
void forEachCornerOf(const MeshTopology& topology, const Eigen::Matrix3Xd& positions, int v, F&& f) {
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  for (const int t : topology.incidentTriangles(v)) {
    const CornerView c = viewFromCorner(positions, triangles, t, cornerOf(triangles, t, v));
    if (!c.degenerate) f(c, t);
  }
}

/** The area a triangle gives to its corner p0 (see mass_matrix.h for the three rules). */
inline double cornerMass(const CornerView& c, MassType type) {
  const double area = 0.5 * c.double_area;
  if (type == MassType::Barycentric) return area / 3.0;
  const double cot0 = c.cotangent(0), cot1 = c.cotangent(1), cot2 = c.cotangent(2);
  if (type == MassType::MixedVoronoi) {
    // A negative cotangent marks the obtuse corner.
    if (cot0 < 0.0) return area / 2.0;
    if (cot1 < 0.0 || cot2 < 0.0) return area / 4.0;
  }
  return ((c.p1 - c.p0).squaredNorm() * cot2 + (c.p2 - c.p0).squaredNorm() * cot1) / 8.0;
}

/** This triangle's part of (L x) at p0 for the cotangent L: the edges p0p1 and p0p2 weighted
 *  by half the cotangent of the opposite angle. */
inline Eigen::Vector3d cotangentLaplacianPart(const CornerView& c) {
  return 0.5 * (c.cotangent(2) * (c.p1 - c.p0) + c.cotangent(1) * (c.p2 - c.p0));
}

}  // namespace detail
}  // namespace pcl_ddg
