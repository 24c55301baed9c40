#include "pcl_ddg/operators/mass_matrix.h"

#include "pcl_ddg/operators/triangle_quantities.h"

namespace pcl_ddg {
namespace {

// Area that triangle t gives to its corner k.
double cornerArea(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xi& tris,
                  const TriangleQuantities& q, Eigen::Index t, int k, MassType type) {
  const double area = q.areas[t];
  if (area == 0.0) return 0.0;
  if (type == MassType::Barycentric) return area / 3.0;
  const int i = tris(k, t), j = tris((k + 1) % 3, t), l = tris((k + 2) % 3, t);
  const double voronoi = ((positions.col(j) - positions.col(i)).squaredNorm() * q.cotangents((k + 2) % 3, t) +
                          (positions.col(l) - positions.col(i)).squaredNorm() * q.cotangents((k + 1) % 3, t)) /
                         8.0;
  if (type == MassType::Voronoi) return voronoi;
  // Mixed: a negative cotangent marks the obtuse corner.
  const bool obtuse_here = q.cotangents(k, t) < 0.0;
  const bool obtuse_elsewhere = q.cotangents((k + 1) % 3, t) < 0.0 || q.cotangents((k + 2) % 3, t) < 0.0;
  if (obtuse_here) return area / 2.0;
  if (obtuse_elsewhere) return area / 4.0;
  return voronoi;
}

}  // namespace

Eigen::VectorXd lumpedMass(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                           const TriangleQuantities& q, MassType type) {
  const Eigen::Matrix3Xi& tris = topology.triangles();
  Eigen::VectorXd mass(topology.numVertices());
  // Gather per vertex (no write conflicts between threads).
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    double sum = 0.0;
    for (const int t : topology.incidentTriangles(v)) {
      const int k = tris(0, t) == v ? 0 : (tris(1, t) == v ? 1 : 2);
      sum += cornerArea(positions, tris, q, t, k, type);
    }
    mass[v] = sum;
  }
  return mass;
}

Eigen::VectorXd lumpedMass(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                           MassType type) {
  return lumpedMass(topology, positions, computeTriangleQuantities(topology, positions), type);
}

Eigen::SparseMatrix<double> massMatrix(const MeshTopology& topology,
                                       const Eigen::Matrix3Xd& positions, MassType type) {
  const Eigen::VectorXd mass = lumpedMass(topology, positions, type);
  Eigen::SparseMatrix<double> m(mass.size(), mass.size());
  m.reserve(Eigen::VectorXi::Ones(mass.size()));
  for (Eigen::Index i = 0; i < mass.size(); ++i) m.insert(i, i) = mass[i];
  m.makeCompressed();
  return m;
}

}  // namespace pcl_ddg
