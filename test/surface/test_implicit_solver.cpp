// Implicit steps by conjugate gradients against the backward Euler operator solved independently
// and against Cholesky on the shared scans, the displacement's digits far from the origin, the
// iteration bound, and Automatic's choice between the two solvers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "pcl_ddg/surface/scalar_field_smoothing.h"
#include "smoothing_support.h"
#include "surface/laplacian_flow.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

MeshSmoothingParameters implicitStep(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                     double h2_units, ImplicitSolver solver) {
  MeshSmoothingParameters p;
  p.time_step = h2_units * squaredEdge(topology, x);
  p.implicit_solver = solver;
  p.thickness_limit = 0.0;  // the flow itself: the steps are compared with backward Euler
  return p;
}

TEST(ImplicitSolver, ConjugateGradientStepsAreTheBackwardEulerOperator) {
  const SurfaceSample torus = makeTorus({24, 0.2, 4});
  const MeshTopology topology = topologyOf(torus);
  MeshSmoothingParameters p = implicitStep(topology, torus.points, 0.5, ImplicitSolver::Cholesky);
  p.iterations = 3;
  p.weight_update = WeightUpdate::Frozen;

  const Eigen::Matrix3Xd reference =
      frozenBackwardEuler(topology, torus.points, p.time_step, p.iterations);

  p.implicit_solver = ImplicitSolver::ConjugateGradient;
  MeshSmoothingReport report;
  const Eigen::Matrix3Xd smoothed = smoothMeshPositions(topology, torus.points, p, &report);
  EXPECT_EQ(report.implicit_solver, ImplicitSolver::ConjugateGradient);
  EXPECT_GT(report.conjugate_gradient_iterations, 3 * 3);
  EXPECT_LT((smoothed - reference).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT((smoothed - torus.points).cwiseAbs().maxCoeff(), 1e-3) << "the step moved the mesh";
}

TEST(ImplicitSolver, ConjugateGradientsAgreeWithCholeskyOnTheSharedScans) {
  // Boundaries, slivers, obtuse triangles and fixed boundaries; steps of 1 and 10 h^2. The two
  // differ by the rounding of the Cholesky solve of the positions, eps * kappa * |x|.
  for (const char* name : {"meshes/bunny.off", "meshes/bun_zipper_res3.ply", "meshes/cow.off",
                           "meshes/bun045_rangegrid_tri.ply"}) {
    const pcl::PolygonMesh mesh = loadMesh(sharedData(name));
    const MeshTopology topology(mesh);
    const Eigen::Matrix3Xd x = vertexPositions(mesh.cloud);
    const double size = x.cwiseAbs().maxCoeff();
    for (const double h2_units : {1.0, 10.0}) {
      for (const BoundaryCondition boundary : {BoundaryCondition::Free, BoundaryCondition::Fixed}) {
        MeshSmoothingParameters p = implicitStep(topology, x, h2_units, ImplicitSolver::Cholesky);
        p.boundary = boundary;
        const Eigen::Matrix3Xd cholesky = smoothMeshPositions(topology, x, p);
        p.implicit_solver = ImplicitSolver::ConjugateGradient;
        const Eigen::Matrix3Xd cg = smoothMeshPositions(topology, x, p);
        const double moved = (cholesky - x).cwiseAbs().maxCoeff();
        const double difference = (cg - cholesky).cwiseAbs().maxCoeff();
        std::printf("%s, %g h^2, %s boundary: moved %.3g, CG - Cholesky %.3g (%.3g eps |x|)\n",
                    name, h2_units, boundary == BoundaryCondition::Free ? "free" : "fixed", moved,
                    difference, difference / (2.2e-16 * size));
        EXPECT_GT(moved, 1e-6 * size) << name;
        EXPECT_LT(difference, 1e4 * 2.2e-16 * size) << name << ", " << h2_units << " h^2";
      }
    }
  }
}

TEST(ImplicitSolver, TheDisplacementKeepsItsDigitsFarFromTheOrigin) {
  // A sphere 1e5 radii from the origin: conjugate gradients solve for the displacement, with
  // L X summed as differences, so the result is the centred one moved, to the rounding of x + d.
  // The bound: moving the sphere rounds each coordinate by at most half an ulp (delta); the step
  // is x' = S x with S = (M - tau L)^-1 M, which commutes with translations (L 1 = 0), so the far
  // result is far + S (x + delta) rounded once more (half an ulp). With no obtuse angle every
  // cotangent weight is positive, M - tau L is an M-matrix, S >= 0 entrywise with rows summing to
  // 1, and |S delta| <= max |delta|: one ulp from the two roundings. Two smaller terms: S itself
  // is built from the rounded far positions, its weights off by a relative ulp / h or so, which
  // moves the displacement d = x / (1 + 2 tau) - x, |d| ~ 2 tau = 2 h^2, by ~ 2h ulps (h = 0.04:
  // 0.08 ulp); conjugate gradients stop at a residual of 1e-12 of d, far below an ulp of 3e5
  // (5.8e-11). Hence 1.25 ulps; measured 0.95. (Cholesky, solving for the positions, is 5.4 ulps
  // off.)
  const SurfaceSample sphere = makeIcosphere(4);
  const MeshTopology topology = topologyOf(sphere);
  double largest_angle = 0.0;
  for (Eigen::Index t = 0; t < sphere.triangles.cols(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = sphere.points.col(sphere.triangles(k, t));
      const Eigen::Vector3d b = sphere.points.col(sphere.triangles((k + 1) % 3, t));
      const Eigen::Vector3d c = sphere.points.col(sphere.triangles((k + 2) % 3, t));
      largest_angle =
          std::max(largest_angle, std::atan2((b - a).cross(c - a).norm(), (b - a).dot(c - a)));
    }
  }
  ASSERT_LT(largest_angle, M_PI / 2) << "an obtuse angle: the one-ulp bound does not hold";
  const Eigen::Vector3d far(1e5, -2e5, 3e5);
  const Eigen::Matrix3Xd moved = sphere.points.colwise() + far;
  const MeshSmoothingParameters p =
      implicitStep(topology, sphere.points, 1.0, ImplicitSolver::ConjugateGradient);
  const Eigen::Matrix3Xd centred = smoothMeshPositions(topology, sphere.points, p);
  const Eigen::Matrix3Xd far_result = smoothMeshPositions(topology, moved, p).colwise() - far;
  const double ulp = std::nextafter(3e5, 1e6) - 3e5;  // the largest coordinates' ulp
  const double error = (far_result - centred).cwiseAbs().maxCoeff();
  std::printf("far from the origin: %.2f ulps of the coordinates (largest angle %.1f deg)\n",
              error / ulp, largest_angle * 180.0 / M_PI);
  EXPECT_LE(error, 1.25 * ulp);
}

TEST(ImplicitSolver, IterationsStayWithinTheBound) {
  const SurfaceSample torus = makeTorus({48, 0.1, 4});
  const MeshTopology topology = topologyOf(torus);
  const double h2 = squaredEdge(topology, torus.points);
  for (const double h2_units : {0.1, 1.0, 10.0, 100.0}) {
    detail::LaplacianFlow flow(topology.numVertices(), {}, CholeskyBackend::Automatic,
                               ImplicitSolver::ConjugateGradient);
    flow.setOperator(laplacian(topology, torus.points), lumpedMass(topology, torus.points));
    Eigen::MatrixXd values = torus.points.transpose();
    flow.implicitStep(values, h2_units * h2);
    const int bound = flow.conjugateGradientIterationBound();
    const double per_column = flow.conjugateGradientIterations() / 3.0;
    std::printf("%g h^2: %.1f iterations per column, bound %d\n", h2_units, per_column, bound);
    EXPECT_GT(per_column, 1.0);
    EXPECT_LE(per_column, bound);
  }
}

TEST(ImplicitSolver, AutomaticIteratesForShortRunsOfSmallStepsAndFactorisesOtherwise) {
  const SurfaceSample torus = makeTorus({48, 0.1, 4});
  const MeshTopology topology = topologyOf(torus);
  const auto chosen = [&](double h2_units, int iterations, WeightUpdate update) {
    MeshSmoothingParameters p =
        implicitStep(topology, torus.points, h2_units, ImplicitSolver::Automatic);
    p.iterations = iterations;
    p.weight_update = update;
    MeshSmoothingReport report;
    smoothMeshPositions(topology, torus.points, p, &report);
    return report.implicit_solver;
  };
  // One step of h^2: some 50 iterations a column at most, against a factorisation.
  EXPECT_EQ(chosen(1.0, 1, WeightUpdate::FrozenStiffness), ImplicitSolver::ConjugateGradient);
  // The mass follows the surface: every step needs a new factorisation. (Ten steps: by 30 the
  // tube of radius 0.4 has collapsed to its core circle, r^2 shrinking by about 2 t.)
  EXPECT_EQ(chosen(1.0, 10, WeightUpdate::FrozenStiffness), ImplicitSolver::ConjugateGradient);
  // A frozen operator: one factorisation serves all 10 steps.
  EXPECT_EQ(chosen(1.0, 10, WeightUpdate::Frozen), ImplicitSolver::Cholesky);
  // A step of 100 h^2 needs some 180 iterations a column: the trial stops.
  EXPECT_EQ(chosen(100.0, 1, WeightUpdate::FrozenStiffness), ImplicitSolver::Cholesky);
}

TEST(ImplicitSolver, HeatFlowOfScalarFieldsWithAFixedBoundaryAgrees) {
  const SurfaceSample saddle = makeSaddle({32, 0.0, 1});
  const MeshTopology topology = topologyOf(saddle);
  Eigen::MatrixXd fields(topology.numVertices(), 2);
  fields.col(0) = saddle.points.row(0).transpose().array().sin();
  fields.col(1) = saddle.points.colwise().squaredNorm().transpose();
  HeatFlowParameters p;
  p.diffusion_time = 4.0 * squaredEdge(topology, saddle.points);
  p.iterations = 2;
  p.boundary = BoundaryCondition::Fixed;
  p.implicit_solver = ImplicitSolver::Cholesky;
  const Eigen::MatrixXd cholesky = smoothScalarFields(topology, saddle.points, fields, p);
  p.implicit_solver = ImplicitSolver::ConjugateGradient;
  const Eigen::MatrixXd cg = smoothScalarFields(topology, saddle.points, fields, p);
  EXPECT_GT((cholesky - fields).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT((cg - cholesky).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
