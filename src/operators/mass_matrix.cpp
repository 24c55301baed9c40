#include "pcl_ddg/operators/mass_matrix.h"

#include "detail/triangle_geometry.h"

namespace pcl_ddg {

Eigen::VectorXd lumpedMass(const MeshTopology& topology, const PositionsRef& positions,
                           MassType type) {
  detail::requireMatchingPositions(topology, positions);
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  Eigen::Matrix3Xd corner_mass(3, triangles.cols());
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    const detail::CornerView c =
        detail::viewFromCorner(positions, triangles, static_cast<int>(t), 0);
    corner_mass.col(t) = c.degenerate ? Eigen::Vector3d::Zero() : detail::cornerMasses(c, type);
  }
  Eigen::VectorXd mass(topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v)
    mass[v] = detail::sumCornerValues(topology, corner_mass, v);
  return mass;
}

Eigen::SparseMatrix<double> massMatrix(const MeshTopology& topology, const PositionsRef& positions,
                                       MassType type) {
  const Eigen::VectorXd mass = lumpedMass(topology, positions, type);
  Eigen::SparseMatrix<double> m(mass.size(), mass.size());
  m.reserve(Eigen::VectorXi::Ones(mass.size()));
  for (Eigen::Index i = 0; i < mass.size(); ++i) m.insert(i, i) = mass[i];
  m.makeCompressed();
  return m;
}

}  // namespace pcl_ddg
