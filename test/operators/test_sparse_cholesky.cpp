// SparseCholesky: both backends solve M - tau L systems to the accuracy of an independent solver,
// refactorise a new matrix with the analysed pattern, and refuse what is not positive definite.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <Eigen/SparseCholesky>
#include <vector>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/operators/sparse_cholesky.h"

namespace pcl_ddg {
namespace test {
namespace {

Eigen::SparseMatrix<double> implicitSystem(const MeshTopology& topology,
                                           const Eigen::Matrix3Xd& points, double tau) {
  Eigen::SparseMatrix<double> system = -tau * laplacian(topology, points);
  system.diagonal() += lumpedMass(topology, points);
  return system;
}

std::vector<CholeskyBackend> availableBackends() {
  std::vector<CholeskyBackend> backends{CholeskyBackend::SimplicialLDLT};
  if (cholmodAvailable()) backends.push_back(CholeskyBackend::Cholmod);
  return backends;
}

// Large enough for CHOLMOD's supernodal path and for blocks of several MiB (those mapped and
// populated).
TEST(SparseCholesky, SolvesAndRefactorisesLikeAnIndependentSolver) {
  Sampling sampling;
  sampling.resolution = 256;
  sampling.jitter = 0.2;
  const SurfaceSample torus = makeTorus(sampling);
  const MeshTopology topology = topologyOf(torus);
  const double h = meanEdgeLength(topology, torus.points);
  const Eigen::SparseMatrix<double> first = implicitSystem(topology, torus.points, h * h);
  const Eigen::SparseMatrix<double> second = implicitSystem(topology, torus.points, 10 * h * h);
  const Eigen::MatrixXd rhs = torus.points.transpose();

  for (const CholeskyBackend backend : availableBackends()) {
    SCOPED_TRACE(toString(backend));
    SparseCholesky solver(backend);
    EXPECT_EQ(solver.backend(), backend);
    solver.compute(first);
    const Eigen::MatrixXd x1 = solver.solve(rhs);
    solver.factorize(second);  // same pattern, new values
    Eigen::MatrixXd x2;
    solver.solve(rhs, x2);

    const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> reference1(first), reference2(second);
    const Eigen::MatrixXd r1 = reference1.solve(rhs), r2 = reference2.solve(rhs);
    EXPECT_LT((x1 - r1).cwiseAbs().maxCoeff(), 1e-12 * r1.cwiseAbs().maxCoeff());
    EXPECT_LT((x2 - r2).cwiseAbs().maxCoeff(), 1e-12 * r2.cwiseAbs().maxCoeff());
    EXPECT_LT((first * x1 - rhs).cwiseAbs().maxCoeff(), 1e-12 * rhs.cwiseAbs().maxCoeff());
  }
}

TEST(SparseCholesky, RefusesAnIndefiniteMatrixAndASolveBeforeTheFactorisation) {
  // -L of a closed mesh plus a negative shift: symmetric, not positive definite.
  const SurfaceSample sphere = makeIcosphere(2);
  const MeshTopology topology = topologyOf(sphere);
  Eigen::SparseMatrix<double> indefinite = -laplacian(topology, sphere.points);
  indefinite.diagonal().array() -= 0.5;
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Ones(indefinite.rows(), 1);

  for (const CholeskyBackend backend : availableBackends()) {
    SCOPED_TRACE(toString(backend));
    SparseCholesky solver(backend);
    EXPECT_THROW(solver.solve(rhs), pcl::ComputeFailedException);
    EXPECT_THROW(solver.compute(indefinite), pcl::ComputeFailedException);
    EXPECT_THROW(solver.solve(rhs), pcl::ComputeFailedException);
  }
}

TEST(SparseCholesky, CholmodIsThereWhenTheBuildFoundIt) {
  // Tests that compare with CHOLMOD run only where it is available: a build that found
  // SuiteSparse must have it, so those comparisons cannot disappear silently.
#ifdef PCL_DDG_EXPECT_CHOLMOD
  EXPECT_TRUE(cholmodAvailable());
#else
  GTEST_SKIP() << "built without CHOLMOD: its comparisons do not run here";
#endif
}

TEST(SparseCholesky, AutomaticPicksCholmodWhenBuiltIn) {
  const SparseCholesky solver;
  EXPECT_EQ(solver.backend(),
            cholmodAvailable() ? CholeskyBackend::Cholmod : CholeskyBackend::SimplicialLDLT);
  if (!cholmodAvailable()) {
    EXPECT_THROW(SparseCholesky{CholeskyBackend::Cholmod}, pcl::BadArgumentException);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
