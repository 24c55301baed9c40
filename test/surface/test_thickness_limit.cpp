// The thickness limit (mesh_smoothing.h, "Thin parts"; smoothing_steps.h, chooseThicknessLimit)
// against an oracle written here from the header's formulas, on the reference operators
// (reference_operators.h: no code shared with laplacian() or lumpedMass()) and Eigen's own
// Cholesky, for explicit and implicit steps and every weight update:
//
//   s_i = max(1, T / (c r_i^2)), T = n tau, r_i the inner-ball radius (innerBallRadii, tested in
//   test_inner_ball.cpp); log s smoothed by one implicit step (M - t L) y = M log s of the input's
//   operator for t = min(T, 4 T / s_median); s = exp(max(y, 0)); vertex i's mass times s_i.
//
// The limit applies to area-averaged explicit and implicit steps only; chooseThicknessLimit
// checks it as its header says.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/surface/inner_ball.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "pcl_ddg/surface/smoothing_steps.h"
#include "reference_operators.h"
#include "smoothing_support.h"

namespace pcl_ddg {
namespace test {
namespace {

/** A thin torus (tube radius 0.12, jittered: the radii vary along it) beside a sphere of radius
 *  3, one mesh of two components: most vertices are thin, so the median vertex is slowed. */
constexpr double kTube = 0.12;

struct ThinAndThick {
  MeshTopology topology;
  Eigen::Matrix3Xd x;
  int torus_vertices;
};

ThinAndThick thinAndThick() {
  const SurfaceSample torus = makeTorus({48, 0.2, 3}, 1.0, kTube);
  const SurfaceSample sphere = makeIcosphere(3, 3.0);
  const int torus_vertices = static_cast<int>(torus.points.cols());
  Eigen::Matrix3Xd x(3, torus.points.cols() + sphere.points.cols());
  x << torus.points, (sphere.points.colwise() + Eigen::Vector3d(6.0, 0.0, 0.0));
  Eigen::Matrix3Xi triangles(3, torus.triangles.cols() + sphere.triangles.cols());
  triangles << torus.triangles, (sphere.triangles.array() + torus_vertices).matrix();
  return {MeshTopology(static_cast<int>(x.cols()), triangles), x, torus_vertices};
}

Eigen::SparseMatrix<double> massMinusTauL(const Eigen::VectorXd& mass,
                                          const Eigen::SparseMatrix<double>& l, double tau) {
  Eigen::SparseMatrix<double> system = -tau * l;
  for (Eigen::Index v = 0; v < mass.size(); ++v) system.coeffRef(v, v) += mass[v];
  return system;
}

/** The header's slowdown s (every vertex of the test meshes has mass). */
Eigen::VectorXd oracleSlowdown(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                               double total_time, double limit) {
  const Eigen::VectorXd r = innerBallRadii(topology, x);
  const int n = static_cast<int>(x.cols());
  Eigen::VectorXd log_s(n);
  for (int v = 0; v < n; ++v)
    log_s[v] = std::log(std::min(std::max(total_time / (limit * r[v] * r[v]), 1.0), 1e12));
  if ((log_s.array() == 0.0).all()) return Eigen::VectorXd::Ones(n);
  std::vector<double> sorted(log_s.data(), log_s.data() + n);
  std::sort(sorted.begin(), sorted.end());
  const double median_slowdown = std::exp(sorted[n / 2]);  // the upper median, as nth_element
  const double t = std::min(total_time, 4.0 * total_time / median_slowdown);
  const Eigen::SparseMatrix<double> l = referenceCotangentLaplacian(topology, x);
  const Eigen::VectorXd m = referenceMass(topology, x);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(massMinusTauL(m, l, t));
  const Eigen::VectorXd smoothed = solver.solve(Eigen::VectorXd(m.cwiseProduct(log_s)));
  return smoothed.array().max(0.0).exp().matrix();
}

/** The flow with masses M s: implicit (M s - tau L) x' = M s x or explicit x' = x + tau (M s)^-1
 *  L x, with L and M of the input (Frozen), M of the current positions (FrozenStiffness), or both
 *  (EveryIteration). */
Eigen::Matrix3Xd oracleFlow(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                            const MeshSmoothingParameters& p) {
  const double total = p.time_step * p.iterations;
  const Eigen::VectorXd s = p.thickness_limit > 0.0
                                ? oracleSlowdown(topology, x, total, p.thickness_limit)
                                : Eigen::VectorXd::Ones(x.cols());
  Eigen::SparseMatrix<double> l = referenceCotangentLaplacian(topology, x);
  Eigen::VectorXd m = referenceMass(topology, x);
  Eigen::MatrixXd values = x.transpose();
  for (int iteration = 1; iteration <= p.iterations; ++iteration) {
    const Eigen::Matrix3Xd current = values.transpose();
    if (iteration > 1 && p.weight_update == WeightUpdate::EveryIteration)
      l = referenceCotangentLaplacian(topology, current);
    if (iteration > 1 && p.weight_update != WeightUpdate::Frozen)
      m = referenceMass(topology, current);
    const Eigen::VectorXd ms = m.cwiseProduct(s);
    if (p.scheme == SmoothingScheme::Explicit) {
      const Eigen::MatrixXd lx = l * values;
      values += p.time_step * (ms.cwiseInverse().asDiagonal() * lx);
    } else {
      const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(
          massMinusTauL(ms, l, p.time_step));
      const Eigen::MatrixXd rhs = ms.asDiagonal() * values;
      values = solver.solve(rhs);
    }
  }
  return values.transpose();
}

double maxDifference(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

TEST(ThicknessLimit, TheOracleSlowsTheTorusAndTheCapOnTheSmoothingTimeBinds) {
  // The test's premises: the torus is thin for the time asked (s > 4 at the median vertex, so the
  // log's smoothing time is capped at 4 T / s_median < T), the sphere is not (s = 1).
  const ThinAndThick m = thinAndThick();
  const double total = 3 * 2.0 * squaredEdge(m.topology, m.x);
  const Eigen::VectorXd r = innerBallRadii(m.topology, m.x);
  EXPECT_NEAR(r.head(m.torus_vertices).mean(), kTube, 0.2 * kTube);
  std::vector<double> s(r.size());
  for (Eigen::Index v = 0; v < r.size(); ++v) s[v] = std::max(total / (0.5 * r[v] * r[v]), 1.0);
  std::vector<double> sorted = s;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_GT(sorted[sorted.size() / 2], 4.5);
  for (int v = m.torus_vertices; v < m.x.cols(); ++v) ASSERT_EQ(s[v], 1.0) << v;
  // and the jittered tube's radii vary, so that the log's smoothing changes it
  const auto torus_radii = r.head(m.torus_vertices);
  EXPECT_GT(torus_radii.maxCoeff() / torus_radii.minCoeff(), 1.2);
}

TEST(ThicknessLimit, ImplicitAndExplicitStepsUnderEveryWeightUpdateEqualTheOracle) {
  const ThinAndThick m = thinAndThick();
  const double h2 = squaredEdge(m.topology, m.x);
  const double bound = explicitStabilityLimit(m.topology, m.x, LaplacianWeights::Cotangent);
  const double extent = (m.x.rowwise().maxCoeff() - m.x.rowwise().minCoeff()).maxCoeff();
  for (const SmoothingScheme scheme : {SmoothingScheme::Implicit, SmoothingScheme::Explicit}) {
    for (const WeightUpdate update :
         {WeightUpdate::Frozen, WeightUpdate::FrozenStiffness, WeightUpdate::EveryIteration}) {
      // The limit c such that the tube's vertices get s = T / (c a^2) of about 12 and 6 (both
      // above 4: the log's smoothing time is capped).
      for (const double slowdown : {12.0, 6.0}) {
        MeshSmoothingParameters p;
        p.scheme = scheme;
        p.weight_update = update;
        // implicit: 3 steps of 2 h^2; explicit: 40 of half the stability bound
        p.time_step = scheme == SmoothingScheme::Implicit ? 2.0 * h2 : 0.5 * bound;
        p.iterations = scheme == SmoothingScheme::Implicit ? 3 : 40;
        p.thickness_limit = p.time_step * p.iterations / (slowdown * kTube * kTube);
        SCOPED_TRACE(testing::Message()
                     << (scheme == SmoothingScheme::Explicit ? "explicit " : "implicit ")
                     << static_cast<int>(update) << " limit " << p.thickness_limit);
        MeshSmoothingReport report;
        const Eigen::Matrix3Xd smoothed = smoothMeshPositions(m.topology, m.x, p, &report);
        const Eigen::Matrix3Xd expected = oracleFlow(m.topology, m.x, p);
        EXPECT_LT(maxDifference(smoothed, expected), 1e-9 * extent);
        // and the limit did something: without it the torus moves elsewhere
        MeshSmoothingParameters none = p;
        none.thickness_limit = 0.0;
        EXPECT_GT(maxDifference(smoothMeshPositions(m.topology, m.x, none), smoothed),
                  1e3 * 1e-9 * extent);
        EXPECT_EQ(report.thin_vertices, m.torus_vertices);
      }
    }
  }
}

TEST(ThicknessLimit, DegreeAveragedAndTaubinStepsHaveNoLimit) {
  // The default limit (0.5) applies to area-averaged steps only: the umbrella operator (uniform
  // weights averaged by degree) and Taubin's filter give the same bits as with no limit.
  const ThinAndThick m = thinAndThick();
  MeshSmoothingParameters p;
  p.weights = LaplacianWeights::Uniform;
  p.average = FlowAverage::Degree;
  p.scheme = SmoothingScheme::Explicit;
  p.time_step = 0.5;
  p.iterations = 5;
  ASSERT_GT(p.thickness_limit, 0.0);
  for (const SmoothingScheme scheme :
       {SmoothingScheme::Explicit, SmoothingScheme::Implicit, SmoothingScheme::Taubin}) {
    p.scheme = scheme;
    MeshSmoothingReport report;
    const Eigen::Matrix3Xd with_default = smoothMeshPositions(m.topology, m.x, p, &report);
    MeshSmoothingParameters none = p;
    none.thickness_limit = 0.0;
    EXPECT_EQ(with_default, smoothMeshPositions(m.topology, m.x, none));
    EXPECT_EQ(report.thin_vertices, 0);
    EXPECT_EQ(report.mean_time_fraction, MeshSmoothingReport().mean_time_fraction);
  }
}

TEST(ThicknessLimit, ChooseThicknessLimitChecksAsItsHeaderSays) {
  const auto parameters = [](SmoothingScheme scheme, const char* weights, const char* average) {
    MeshSmoothingParameters p;
    p.scheme = scheme;
    chooseOperator(p, weights, average, false);
    return p;
  };
  const double default_limit = MeshSmoothingParameters().thickness_limit;
  for (const SmoothingScheme scheme : {SmoothingScheme::Implicit, SmoothingScheme::Explicit}) {
    MeshSmoothingParameters p = parameters(scheme, "cotan", "area");
    chooseThicknessLimit(p, std::nullopt, "-limit");  // none given: the default stays
    EXPECT_EQ(p.thickness_limit, default_limit);
    chooseThicknessLimit(p, 0.0, "-limit");  // 0: no limit, accepted
    EXPECT_EQ(p.thickness_limit, 0.0);
    chooseThicknessLimit(p, 2.5, "-limit");
    EXPECT_EQ(p.thickness_limit, 2.5);
    for (const double bad : {-0.5, std::nan(""), HUGE_VAL}) {
      MeshSmoothingParameters q = parameters(scheme, "cotan", "area");
      EXPECT_THROW(chooseThicknessLimit(q, bad, "-limit"), pcl::BadArgumentException) << bad;
    }
  }
  // A positive limit with Taubin's filter or a degree average is refused, naming the option; 0 is
  // accepted there (it asks for no limit).
  for (MeshSmoothingParameters p : {parameters(SmoothingScheme::Taubin, "", ""),
                                    parameters(SmoothingScheme::Explicit, "umbrella", ""),
                                    parameters(SmoothingScheme::Implicit, "cotan", "degree"),
                                    parameters(SmoothingScheme::Explicit, "uniform", "degree")}) {
    try {
      chooseThicknessLimit(p, 0.5, "the_option");
      ADD_FAILURE() << "accepted a limit for " << static_cast<int>(p.scheme) << " "
                    << static_cast<int>(p.average);
    } catch (const pcl::BadArgumentException& e) {
      EXPECT_NE(std::string(e.what()).find("the_option"), std::string::npos) << e.what();
    }
    chooseThicknessLimit(p, 0.0, "the_option");
    EXPECT_EQ(p.thickness_limit, 0.0);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
