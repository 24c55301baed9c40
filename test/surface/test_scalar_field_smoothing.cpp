// Heat flow of scalar fields: conservation, the decay rate of an eigenfunction of the sphere,
// boundary conditions, smoothing a noisy curvature, and bad fields.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <cmath>
#include <limits>
#include <random>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/surface/scalar_field_smoothing.h"
#include "reference_operators.h"
#include "smoothing_support.h"

namespace pcl_ddg {
namespace test {
namespace {

Eigen::VectorXd noise(Eigen::Index n, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::VectorXd values(n);
  for (Eigen::Index i = 0; i < n; ++i) values[i] = gauss(random);
  return values;
}

TEST(ScalarFieldSmoothing, BothSchemesConserveTheMassWeightedSumOnClosedMeshes) {
  for (const SurfaceSample& surface : {makeIcosphere(3, 1.0, 0.2), makeTorus({32, 0.2, 3})}) {
    const MeshTopology topology = topologyOf(surface);
    const Eigen::VectorXd mass = lumpedMass(topology, surface.points);
    const Eigen::VectorXd field = noise(surface.points.cols(), 5).array() + 3.0;
    const double h = meanEdgeLength(topology, surface.points);
    for (const SmoothingScheme scheme : {SmoothingScheme::Explicit, SmoothingScheme::Implicit}) {
      HeatFlowParameters p;
      p.scheme = scheme;
      p.iterations = 20;
      p.diffusion_time =
          p.iterations * (scheme == SmoothingScheme::Explicit
                              ? 0.5 * explicitStabilityLimit(topology, surface.points)
                              : 0.5 * h * h);
      const Eigen::VectorXd smoothed = smoothScalarField(topology, surface.points, field, p);
      EXPECT_NEAR(mass.dot(smoothed) / mass.dot(field), 1.0, 1e-12);
      // And it did smooth: the mass-weighted variance dropped.
      const double mean = mass.dot(field) / mass.sum();
      const auto variance = [&](const Eigen::VectorXd& f) {
        return mass.dot((f.array() - mean).square().matrix()) / mass.sum();
      };
      EXPECT_LT(variance(smoothed), 0.5 * variance(field));
    }
  }
}

TEST(ScalarFieldSmoothing, AFirstSphericalHarmonicDecaysAtItsEigenvalue) {
  // On the unit sphere f = z satisfies Laplace-Beltrami f = -2 f: one implicit step divides it by
  // 1 + 2 tau, one explicit step multiplies it by 1 - 2 tau (up to the O(h^2) discretisation).
  double errors[2];
  for (const int level : {3, 5}) {
    const SurfaceSample sphere = makeIcosphere(level);
    const MeshTopology topology = topologyOf(sphere);
    const Eigen::VectorXd z = sphere.points.row(2).transpose();
    HeatFlowParameters p;
    p.diffusion_time = 0.05;
    p.scheme = SmoothingScheme::Implicit;
    const Eigen::VectorXd implicit_result = smoothScalarField(topology, sphere.points, z, p);
    const double implicit_error =
        (implicit_result - z / (1.0 + 2.0 * p.diffusion_time)).cwiseAbs().maxCoeff();
    p.scheme = SmoothingScheme::Explicit;
    p.diffusion_time = 0.5 * explicitStabilityLimit(topology, sphere.points);
    const Eigen::VectorXd explicit_result = smoothScalarField(topology, sphere.points, z, p);
    const double explicit_error =
        (explicit_result - z * (1.0 - 2.0 * p.diffusion_time)).cwiseAbs().maxCoeff();
    std::printf("level %d: implicit decay error %.2e, explicit %.2e\n", level, implicit_error,
                explicit_error);
    EXPECT_LT(implicit_error, level == 3 ? 3e-4 : 3e-5);
    EXPECT_LT(explicit_error, level == 3 ? 1e-4 : 2e-6);
    errors[level == 3 ? 0 : 1] = implicit_error;
  }
  // Two levels are h / 4: the eigenvalue is second-order accurate.
  EXPECT_GT(std::log(errors[0] / errors[1]) / std::log(4.0), 1.8);
}

// HeatFlowParameters::mass chooses M in both schemes: each type's flow against backward and
// forward Euler on the reference operators (reference_operators.h: L and that type's M assembled
// triangle by triangle, solved by Eigen's SimplicialLLT), and the three types' results differ on a
// jittered sphere, whose obtuse triangles make the Voronoi, mixed and barycentric cells differ.
TEST(ScalarFieldSmoothing, TheMassParameterIsTheMassOfBothSchemes) {
  // The premises: every Voronoi cell is positive (the implicit system stays definite), and the
  // types differ. The first jittered sphere (by seed) that meets them: the jitter's draws are in
  // an order each compiler chooses, so a fixed seed is not the same mesh under GCC and Clang.
  SurfaceSample sphere;
  Eigen::VectorXd mixed, voronoi, barycentric;
  for (int seed = 3;; ++seed) {
    ASSERT_LT(seed, 60) << "no jittered sphere with positive Voronoi cells";
    sphere = makeIcosphere(3, 1.0, 0.2, seed);
    const MeshTopology candidate = topologyOf(sphere);
    mixed = referenceMass(candidate, sphere.points, MassType::MixedVoronoi);
    voronoi = referenceMass(candidate, sphere.points, MassType::Voronoi);
    barycentric = referenceMass(candidate, sphere.points, MassType::Barycentric);
    if (voronoi.minCoeff() > 0.0 && (voronoi - mixed).cwiseAbs().maxCoeff() > 1e-3 * mixed.mean() &&
        (barycentric - mixed).cwiseAbs().maxCoeff() > 1e-3 * mixed.mean())
      break;
  }
  const MeshTopology topology = topologyOf(sphere);
  const Eigen::VectorXd field = noise(sphere.points.cols(), 8).array() + 2.0;
  const double h = meanEdgeLength(topology, sphere.points);
  const Eigen::SparseMatrix<double> l = referenceCotangentLaplacian(topology, sphere.points);
  const double stable_step = 0.5 * explicitStabilityLimit(topology, sphere.points);
  Eigen::VectorXd results[2][3];
  for (const SmoothingScheme scheme : {SmoothingScheme::Implicit, SmoothingScheme::Explicit}) {
    const bool implicit = scheme == SmoothingScheme::Implicit;
    int t = 0;
    for (const MassType type : {MassType::Barycentric, MassType::Voronoi, MassType::MixedVoronoi}) {
      SCOPED_TRACE(testing::Message() << (implicit ? "implicit" : "explicit") << ", mass type "
                                      << static_cast<int>(type));
      HeatFlowParameters p;
      p.scheme = scheme;
      p.mass = type;
      p.iterations = implicit ? 3 : 10;
      // Half the mixed mass's stability limit: below the other types' too (checked by the
      // reference not blowing up, and by agreeing with it).
      const double tau = implicit ? h * h : 0.5 * stable_step;
      p.diffusion_time = p.iterations * tau;
      p.implicit_solver = ImplicitSolver::Cholesky;
      const Eigen::VectorXd ours = smoothScalarField(topology, sphere.points, field, p);
      Eigen::VectorXd expected;
      const Eigen::VectorXd m = referenceMass(topology, sphere.points, type);
      if (implicit) {
        expected = referenceBackwardEuler(topology, sphere.points, field, tau, p.iterations, type);
      } else {
        expected = field;
        for (int i = 0; i < p.iterations; ++i) {
          const Eigen::VectorXd lf = l * expected;
          expected += tau * lf.cwiseQuotient(m);
        }
      }
      EXPECT_LT((ours - expected).cwiseAbs().maxCoeff(), 1e-10 * field.cwiseAbs().maxCoeff());
      // and the flow conserves that type's mass-weighted sum (1^T L = 0)
      EXPECT_NEAR(m.dot(ours) / m.dot(field), 1.0, 1e-12);
      results[implicit ? 0 : 1][t++] = ours;
    }
  }
  for (int scheme = 0; scheme < 2; ++scheme) {
    for (int t = 0; t < 2; ++t) {
      EXPECT_GT((results[scheme][t] - results[scheme][2]).cwiseAbs().maxCoeff(), 1e-4)
          << "scheme " << scheme << ", type " << t << " gives the mixed mass's result";
    }
  }
}

TEST(ScalarFieldSmoothing, InsulatedOrFixedBoundary) {
  const SurfaceSample plane = makePlane({16, 0.2, 9});
  const MeshTopology topology = topologyOf(plane);
  const Eigen::VectorXd field = noise(plane.points.cols(), 2);
  HeatFlowParameters p;
  p.diffusion_time = 0.05;
  p.iterations = 4;
  // Free (insulated): the mass-weighted sum is conserved on an open mesh too.
  const Eigen::VectorXd mass = lumpedMass(topology, plane.points);
  const Eigen::VectorXd insulated = smoothScalarField(topology, plane.points, field, p);
  EXPECT_NEAR(mass.dot(insulated), mass.dot(field), 1e-12 * mass.dot(field.cwiseAbs()));
  // Fixed (Dirichlet): boundary values kept exactly; a linear field (harmonic) is then a fixed
  // point of the cotangent flow on a planar mesh.
  p.boundary = BoundaryCondition::Fixed;
  const Eigen::VectorXd fixed = smoothScalarField(topology, plane.points, field, p);
  const Eigen::VectorXd linear =
      (2.0 * plane.points.row(0) - 3.0 * plane.points.row(1)).transpose().array() + 1.0;
  const Eigen::VectorXd linear_after = smoothScalarField(topology, plane.points, linear, p);
  for (int v = 0; v < topology.numVertices(); ++v) {
    if (topology.isBoundary(v)) EXPECT_EQ(fixed[v], field[v]);
  }
  EXPECT_LT((linear_after - linear).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ScalarFieldSmoothing, SmoothingANoisyCurvatureBringsItCloserToTheTruth) {
  // The cotangent mean curvature of a jittered torus is noisy (it does not converge, see
  // test_curvature); a short heat flow of about two edge lengths squared cuts its error.
  const SurfaceSample torus = makeTorus({96, 0.15, 4});
  const MeshTopology topology = topologyOf(torus);
  const VertexCurvatures curvature = computeCurvatures(topology, torus.points);
  const double h = meanEdgeLength(topology, torus.points);
  HeatFlowParameters p;
  p.diffusion_time = 2.0 * h * h;
  const Eigen::VectorXd smoothed =
      smoothScalarField(topology, torus.points, curvature.mean_curvature, p);
  const auto rms = [&](const Eigen::VectorXd& h_estimate) {
    return std::sqrt((h_estimate - torus.mean_curvature).squaredNorm() / h_estimate.size());
  };
  std::printf("jittered torus H RMS error: %.3e raw, %.3e after heat flow of 2 h^2\n",
              rms(curvature.mean_curvature), rms(smoothed));
  EXPECT_LT(rms(smoothed), 0.5 * rms(curvature.mean_curvature));
}

TEST(ScalarFieldSmoothing, NonFiniteValuesOnlyWhereThereIsNoMass) {
  // Two triangles and an isolated vertex (index 4).
  Eigen::Matrix3Xd x(3, 5);
  x << 0, 1, 1, 0, 5,  //
      0, 0, 1, 1, 5,   //
      0, 0, 0, 0, 5;
  Eigen::Matrix3Xi t(3, 2);
  t << 0, 0,  //
      1, 2,   //
      2, 3;
  const MeshTopology topology(5, t);
  HeatFlowParameters p;
  p.diffusion_time = 0.1;
  Eigen::VectorXd field(5);
  field << 1, 2, 3, 4, std::nan("");
  const Eigen::VectorXd smoothed = smoothScalarField(topology, x, field, p);
  EXPECT_TRUE(std::isnan(smoothed[4])) << "kept on the isolated vertex";
  EXPECT_TRUE(smoothed.head(4).allFinite());
  field[1] = std::numeric_limits<double>::infinity();
  try {
    smoothScalarField(topology, x, field, p);
    FAIL() << "expected BadArgumentException";
  } catch (const pcl::BadArgumentException& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(smoothScalarField(topology, x, Eigen::VectorXd::Ones(3), p),
               pcl::BadArgumentException);
  p.diffusion_time = -1.0;
  EXPECT_THROW(smoothScalarField(topology, x, Eigen::VectorXd::Ones(5), p),
               pcl::BadArgumentException);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
