#include "smoothing_support.h"

#include <Eigen/SparseCholesky>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/mass_matrix.h"

namespace pcl_ddg {
namespace test {

double squaredEdge(const MeshTopology& topology, const Eigen::Matrix3Xd& x) {
  const double h = meanEdgeLength(topology, x);
  return h * h;
}

Eigen::Matrix3Xd frozenBackwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                     double tau, int steps) {
  const Eigen::SparseMatrix<double> l = laplacian(topology, x);
  const Eigen::VectorXd m = lumpedMass(topology, x);
  Eigen::SparseMatrix<double> system = -tau * l;
  for (int v = 0; v < topology.numVertices(); ++v) system.coeffRef(v, v) += m[v];
  const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> solver(system);
  Eigen::MatrixXd values = x.transpose();
  for (int i = 0; i < steps; ++i) {
    const Eigen::MatrixXd rhs = m.asDiagonal() * values;
    values = solver.solve(rhs);
  }
  return values.transpose();
}

}  // namespace test
}  // namespace pcl_ddg
