#include "smoothing_support.h"

#include <Eigen/SparseCholesky>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "reference_operators.h"

namespace pcl_ddg {
namespace test {

double squaredEdge(const MeshTopology& topology, const Eigen::Matrix3Xd& x) {
  const double h = meanEdgeLength(topology, x);
  return h * h;
}

Eigen::MatrixXd referenceBackwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                       const Eigen::MatrixXd& values, double tau, int steps,
                                       MassType mass) {
  const Eigen::SparseMatrix<double> l = referenceCotangentLaplacian(topology, x);
  const Eigen::VectorXd m = referenceMass(topology, x, mass);
  Eigen::SparseMatrix<double> system = -tau * l;
  for (int v = 0; v < topology.numVertices(); ++v) system.coeffRef(v, v) += m[v];
  const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> solver(system);
  Eigen::MatrixXd result = values;
  for (int i = 0; i < steps; ++i) {
    const Eigen::MatrixXd rhs = m.asDiagonal() * result;
    result = solver.solve(rhs);
  }
  return result;
}

Eigen::Matrix3Xd frozenBackwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                     double tau, int steps, MassType mass) {
  return referenceBackwardEuler(topology, x, x.transpose(), tau, steps, mass).transpose();
}

Eigen::Matrix3Xd frozenForwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                    double tau, int steps) {
  const Eigen::SparseMatrix<double> l = referenceCotangentLaplacian(topology, x);
  const Eigen::VectorXd inverse_mass = referenceMass(topology, x).cwiseInverse();
  Eigen::MatrixXd values = x.transpose();
  for (int i = 0; i < steps; ++i) {
    const Eigen::MatrixXd lx = l * values;
    values += tau * (inverse_mass.asDiagonal() * lx);
  }
  return values.transpose();
}

}  // namespace test
}  // namespace pcl_ddg
