#include "reference_operators.h"

#include <Eigen/Geometry>
#include <vector>

#include "pcl_ddg/mesh/mesh_geometry.h"

namespace pcl_ddg {
namespace test {
namespace {

double cotangentAt(const Eigen::Vector3d& corner, const Eigen::Vector3d& u,
                   const Eigen::Vector3d& v) {
  const Eigen::Vector3d e1 = u - corner, e2 = v - corner;
  return e1.dot(e2) / e1.cross(e2).norm();
}

}  // namespace

Eigen::SparseMatrix<double> referenceCotangentLaplacian(const MeshTopology& topology,
                                                        const Eigen::Matrix3Xd& x) {
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(12 * triangles.cols());
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    const int v[3] = {triangles(0, t), triangles(1, t), triangles(2, t)};
    // Degenerate triangles carry no weight: the library's documented relative guard
    // (mesh_geometry.h), so that both sides drop the same triangles.
    if (isDegenerateTriangle(x.col(v[0]), x.col(v[1]), x.col(v[2]))) continue;
    for (int k = 0; k < 3; ++k) {
      // The angle at corner k is opposite the edge ij.
      const int i = v[(k + 1) % 3], j = v[(k + 2) % 3];
      const double w = 0.5 * cotangentAt(x.col(v[k]), x.col(i), x.col(j));
      entries.emplace_back(i, j, w);
      entries.emplace_back(j, i, w);
      entries.emplace_back(i, i, -w);
      entries.emplace_back(j, j, -w);
    }
  }
  Eigen::SparseMatrix<double> l(topology.numVertices(), topology.numVertices());
  l.setFromTriplets(entries.begin(), entries.end());
  return l;
}

double referenceCornerArea(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                           const Eigen::Vector3d& p2, int i, MassType type) {
  const Eigen::Vector3d p[3] = {p0, p1, p2};
  const Eigen::Vector3d normal = (p1 - p0).cross(p2 - p0);
  const double area = 0.5 * normal.norm();
  if (type == MassType::Barycentric) return area / 3.0;
  if (type == MassType::MixedVoronoi) {
    const auto obtuse = [&p](int k) {
      return (p[(k + 1) % 3] - p[k]).dot(p[(k + 2) % 3] - p[k]) < 0.0;
    };
    if (obtuse(i)) return area / 2.0;
    if (obtuse((i + 1) % 3) || obtuse((i + 2) % 3)) return area / 4.0;
  }
  // Circumcentre of the triangle, then the corner's cell: corner, midpoint towards the next
  // corner, circumcentre, midpoint towards the previous one; signed by the triangle's normal.
  // Everything relative to the corners, so that the cells keep their digits far from the origin.
  const Eigen::Vector3d a = p1 - p0, b = p2 - p0;
  const Eigen::Vector3d centre_from_p0 =
      (a.squaredNorm() * b.cross(normal) + b.squaredNorm() * normal.cross(a)) /
      (2.0 * normal.squaredNorm());
  const Eigen::Vector3d& q = p[i];
  const Eigen::Vector3d o = (p0 - q) + centre_from_p0;
  const Eigen::Vector3d next = 0.5 * (p[(i + 1) % 3] - q);
  const Eigen::Vector3d previous = 0.5 * (p[(i + 2) % 3] - q);
  const Eigen::Vector3d unit = normal / normal.norm();
  return 0.5 * (next.cross(o) + o.cross(previous)).dot(unit);
}

Eigen::VectorXd referenceMass(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                              MassType type) {
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(topology.numVertices());
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    const Eigen::Vector3d a = x.col(triangles(0, t)), b = x.col(triangles(1, t)),
                          c = x.col(triangles(2, t));
    if (isDegenerateTriangle(a, b, c)) continue;
    for (int i = 0; i < 3; ++i) mass[triangles(i, t)] += referenceCornerArea(a, b, c, i, type);
  }
  return mass;
}

}  // namespace test
}  // namespace pcl_ddg
