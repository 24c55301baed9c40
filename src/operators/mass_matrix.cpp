#include "pcl_ddg/operators/mass_matrix.h"

#include "triangle_geometry.h"

namespace pcl_ddg {

Eigen::VectorXd lumpedMass(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                           MassType type) {
  detail::requireMatchingPositions(topology, positions);
  Eigen::VectorXd mass(topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    double sum = 0.0;
    detail::forEachCornerOf(topology, positions, v,
                            [&](const detail::CornerView& c, int) { sum += detail::cornerMass(c, type); });
    mass[v] = sum;
  }
  return mass;
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
