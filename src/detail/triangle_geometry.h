#pragma once
// Geometry of one triangle, computed where it is needed. The operators gather per vertex (each
// vertex visits its own triangles, so threads never write to shared entries). Operators that
// need several quantities per corner recompute the triangle from each corner; those that need
// one number per corner (masses, face normals) compute each triangle once into a per-triangle
// array first, which measured twice as fast as recomputing.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/operators/mass_matrix.h"

namespace pcl_ddg {
namespace detail {

/** Throws InvalidMeshException unless positions has one finite column per topology vertex. */
void requireMatchingPositions(const MeshTopology& topology, const PositionsRef& positions);

/** Triangle t seen from its corner k: p0 is that corner, p1 and p2 follow in winding order. */
struct CornerView {
  Eigen::Vector3d p0, p1, p2;
  Eigen::Vector3d area_vector;  ///< (p1 - p0) x (p2 - p0) / 2, zero if degenerate
  double double_area = 0.0;     ///< |(p1 - p0) x (p2 - p0)|, zero if degenerate
  bool degenerate = true;

  /** p0, p1, p2 by index. */
  const Eigen::Vector3d& point(int corner) const {
    return corner == 0 ? p0 : (corner == 1 ? p1 : p2);
  }
  /** Cotangent of the angle at corner 0, 1 or 2. Only for non-degenerate triangles. */
  double cotangent(int corner) const { return cornerDot(corner) / double_area; }
  /** Interior angle at a corner (atan2 stays accurate for tiny and obtuse angles). */
  double angle(int corner = 0) const { return std::atan2(double_area, cornerDot(corner)); }

 private:
  double cornerDot(int corner) const {
    const Eigen::Vector3d& o = point(corner);
    return (point((corner + 1) % 3) - o).dot(point((corner + 2) % 3) - o);
  }
};

/**
 * Whether a sum of vectors has cancelled: its length is at rounding level of the sum of the
 * lengths of its terms (a face and its reversed duplicate; a fin folded onto itself). Its
 * direction is then noise, and so is any sign taken from it.
 */
inline bool hasCancelled(const Eigen::Vector3d& sum, double sum_of_lengths) {
  constexpr double kRelativeTolerance = 1e-8;
  return !(sum.norm() > kRelativeTolerance * sum_of_lengths);
}

inline int cornerOf(const Eigen::Matrix3Xi& triangles, int t, int v) {
  return triangles(0, t) == v ? 0 : (triangles(1, t) == v ? 1 : 2);
}

inline CornerView viewFromCorner(const PositionsRef& positions, const Eigen::Matrix3Xi& triangles,
                                 int t, int k) {
  CornerView c;
  c.p0 = positions.col(triangles(k, t));
  c.p1 = positions.col(triangles((k + 1) % 3, t));
  c.p2 = positions.col(triangles((k + 2) % 3, t));
  // Area and degeneracy from the triangle's first corner whatever the view, so that every corner
  // sees bit-identical numbers: cotangents of a sliver computed from different corners would
  // differ in their leading digits and make L unsymmetric.
  const Eigen::Vector3d& a = positions.col(triangles(0, t));
  const Eigen::Vector3d& b = positions.col(triangles(1, t));
  const Eigen::Vector3d& d = positions.col(triangles(2, t));
  if (isDegenerateTriangle(a, b, d)) return c;
  c.area_vector = 0.5 * (b - a).cross(d - a);
  c.double_area = 2.0 * c.area_vector.norm();
  c.degenerate = false;
  return c;
}

/** Calls f(view, t) for every non-degenerate triangle t of v, viewed from v's corner. */
template <typename F>
void forEachCornerOf(const MeshTopology& topology, const PositionsRef& positions, int v, F&& f) {
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  for (const int t : topology.incidentTriangles(v)) {
    const CornerView c = viewFromCorner(positions, triangles, t, cornerOf(triangles, t, v));
    if (!c.degenerate) f(c, t);
  }
}

/** The area a triangle gives to its corner i (see mass_matrix.h for the three rules), given the
 *  cotangents of its three angles. */
inline double cornerMassAt(const CornerView& c, MassType type, int i, const double (&cot)[3]) {
  const double area = 0.5 * c.double_area;
  if (type == MassType::Barycentric) return area / 3.0;
  const int j = (i + 1) % 3, k = (i + 2) % 3;
  if (type == MassType::MixedVoronoi) {
    // A negative cotangent marks the obtuse corner.
    if (cot[i] < 0.0) return area / 2.0;
    if (cot[j] < 0.0 || cot[k] < 0.0) return area / 4.0;
  }
  const Eigen::Vector3d& o = c.point(i);
  return ((c.point(j) - o).squaredNorm() * cot[k] + (c.point(k) - o).squaredNorm() * cot[j]) / 8.0;
}

/** The area a triangle gives to its corner p0. */
inline double cornerMass(const CornerView& c, MassType type) {
  const double cot[3] = {c.cotangent(0), c.cotangent(1), c.cotangent(2)};
  return cornerMassAt(c, type, 0, cot);
}

/** The areas a triangle gives to its corners p0, p1, p2. */
inline Eigen::Vector3d cornerMasses(const CornerView& c, MassType type) {
  const double cot[3] = {c.cotangent(0), c.cotangent(1), c.cotangent(2)};
  return {cornerMassAt(c, type, 0, cot), cornerMassAt(c, type, 1, cot),
          cornerMassAt(c, type, 2, cot)};
}

/** Sums values(corner of v in t, t) over the triangles t of v: the gather half of a face pass. */
inline double sumCornerValues(const MeshTopology& topology, const Eigen::Matrix3Xd& values, int v) {
  double sum = 0.0;
  for (const int t : topology.incidentTriangles(v))
    sum += values(cornerOf(topology.triangles(), t, v), t);
  return sum;
}

/** This triangle's part of (L x) at p0 for the cotangent L: the edges p0p1 and p0p2 weighted
 *  by half the cotangent of the opposite angle. */
inline Eigen::Vector3d cotangentLaplacianPart(const CornerView& c) {
  return 0.5 * (c.cotangent(2) * (c.p1 - c.p0) + c.cotangent(1) * (c.p2 - c.p0));
}

/** What a vertex gathers from its own triangles in one pass: the curvatures, the mean-curvature
 *  normal and the mean-curvature vertex normals all start from it. */
struct VertexSums {
  double mass = 0.0;                                      ///< the vertex's area (MassType)
  double angle_sum = 0.0;                                 ///< with_angles only
  Eigen::Vector3d laplace = Eigen::Vector3d::Zero();      ///< (L x)_v, cotangent L
  Eigen::Vector3d area_normal = Eigen::Vector3d::Zero();  ///< sum of the area vectors
  double area = 0.0;                                      ///< sum of |area vectors|
};

/** v's sums; with_angles also adds its corners' angles (an atan2 each, which normals skip). */
template <bool with_angles>
VertexSums gatherVertexSums(const MeshTopology& topology, const PositionsRef& positions, int v,
                            MassType mass) {
  VertexSums s;
  forEachCornerOf(topology, positions, v, [&](const CornerView& c, int) {
    s.mass += cornerMass(c, mass);
    if constexpr (with_angles) s.angle_sum += c.angle();
    s.laplace += cotangentLaplacianPart(c);
    s.area_normal += c.area_vector;
    s.area += 0.5 * c.double_area;
  });
  return s;
}

/** The angle defect of a vertex whose corners' angles sum to angle_sum: 2 pi minus that sum
 *  inside, pi minus it on the boundary (the discrete Gauss curvature times the area). */
inline double angleDefectAt(bool boundary, double angle_sum) {
  constexpr double kPi = 3.14159265358979323846;
  return (boundary ? kPi : 2.0 * kPi) - angle_sum;
}

}  // namespace detail
}  // namespace pcl_ddg
