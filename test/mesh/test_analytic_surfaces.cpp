// The generators are the ground truth of every other test, so they are tested first: points lie on
// the surface, normals are unit and orthogonal to it, curvatures obey their own identities, and
// the meshes have the topology of the surface.
#include <gtest/gtest.h>

#include <cmath>

#include "analytic_surfaces.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Implicit equation residual of each surface (zero on the surface).
double planeResidual(const Eigen::Vector3d& p) {
  return p.z();
}
double sphereResidual(const Eigen::Vector3d& p) {
  return p.norm() - 1.0;
}
double cylinderResidual(const Eigen::Vector3d& p) {
  return std::hypot(p.x(), p.y()) - 1.0;
}
double torusResidual(const Eigen::Vector3d& p) {
  return std::hypot(std::hypot(p.x(), p.y()) - 1.0, p.z()) - 0.4;
}
double saddleResidual(const Eigen::Vector3d& p) {
  return p.z() - 0.5 * (p.x() * p.x() - p.y() * p.y());
}
double paraboloidResidual(const Eigen::Vector3d& p) {
  return p.z() - 0.5 * (p.x() * p.x() + p.y() * p.y());
}

struct Case {
  const char* name;
  SurfaceSample sample;
  double (*residual)(const Eigen::Vector3d&);
};

std::vector<Case> allSurfaces(double jitter) {
  const Sampling s{24, jitter, 7};
  return {{"plane", makePlane(s), planeResidual},
          {"sphere", makeIcosphere(3, 1.0, jitter), sphereResidual},
          {"cylinder", makeCylinder(s), cylinderResidual},
          {"torus", makeTorus(s), torusResidual},
          {"saddle", makeSaddle(s), saddleResidual},
          {"paraboloid", makeParaboloid(s), paraboloidResidual}};
}

// Normal of the implicit surface by central differences of the residual.
Eigen::Vector3d residualGradient(double (*f)(const Eigen::Vector3d&), const Eigen::Vector3d& p) {
  const double h = 1e-6;
  Eigen::Vector3d g;
  for (int d = 0; d < 3; ++d) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[d] = h;
    g[d] = (f(p + e) - f(p - e)) / (2 * h);
  }
  return g.normalized();
}

TEST(AnalyticSurfaces, PointsOnSurfaceWithUnitNormalsOrthogonalToIt) {
  for (double jitter : {0.0, 0.1}) {
    for (const Case& c : allSurfaces(jitter)) {
      SCOPED_TRACE(c.name);
      for (Eigen::Index i = 0; i < c.sample.points.cols(); ++i) {
        const Eigen::Vector3d p = c.sample.points.col(i), n = c.sample.normals.col(i);
        ASSERT_NEAR(c.residual(p), 0.0, 1e-12);
        ASSERT_NEAR(n.norm(), 1.0, 1e-12);
        ASSERT_NEAR(std::abs(n.dot(residualGradient(c.residual, p))), 1.0, 1e-8);
      }
    }
  }
}

TEST(AnalyticSurfaces, PrincipalFrameIsOrthonormalTangentAndOrdered) {
  for (const Case& c : allSurfaces(0.08)) {
    SCOPED_TRACE(c.name);
    const SurfaceSample& s = c.sample;
    for (Eigen::Index i = 0; i < s.points.cols(); ++i) {
      ASSERT_GE(s.kappa1[i], s.kappa2[i]);
      ASSERT_NEAR(s.mean_curvature[i], 0.5 * (s.kappa1[i] + s.kappa2[i]), 1e-14);
      ASSERT_NEAR(s.gauss_curvature[i], s.kappa1[i] * s.kappa2[i], 1e-14);
      ASSERT_NEAR(s.dir1.col(i).norm(), 1.0, 1e-12);
      ASSERT_NEAR(s.dir2.col(i).norm(), 1.0, 1e-12);
      ASSERT_NEAR(s.dir1.col(i).dot(s.dir2.col(i)), 0.0, 1e-12);
      ASSERT_NEAR(s.dir1.col(i).dot(s.normals.col(i)), 0.0, 1e-12);
      ASSERT_NEAR(s.dir2.col(i).dot(s.normals.col(i)), 0.0, 1e-12);
    }
  }
}

// Curvature along a principal direction equals the normal curvature of the surface there, which
// second differences of the implicit surface give independently of the generator's formulas.
TEST(AnalyticSurfaces, PrincipalCurvaturesMatchNormalCurvatureOfTheSurface) {
  for (const Case& c : allSurfaces(0.0)) {
    SCOPED_TRACE(c.name);
    const SurfaceSample& s = c.sample;
    for (Eigen::Index i = 0; i < s.points.cols(); i += 7) {
      const Eigen::Vector3d p = s.points.col(i), n = s.normals.col(i);
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector3d t = k == 0 ? s.dir1.col(i) : s.dir2.col(i);
        const double kappa = k == 0 ? s.kappa1[i] : s.kappa2[i];
        // Walk along t, project back onto the surface along n (Newton on the residual), and read
        // the height of the surface over the tangent plane: h(s) = -kappa s^2 / 2 + O(s^3).
        const double step = 1e-3;
        double height_sum = 0.0;
        for (double sign : {-1.0, 1.0}) {
          double h = 0.0;
          for (int it = 0; it < 50; ++it) {
            const Eigen::Vector3d q = p + sign * step * t + h * n;
            const double r = c.residual(q);
            const double dr = (c.residual(q + 1e-7 * n) - c.residual(q - 1e-7 * n)) / 2e-7;
            h -= r / dr;
          }
          height_sum += h;
        }
        EXPECT_NEAR(-height_sum / (step * step), kappa, 2e-3);
      }
    }
  }
}

TEST(AnalyticSurfaces, MeshesHaveTheTopologyOfTheSurface) {
  for (const Case& c : allSurfaces(0.1)) {
    SCOPED_TRACE(c.name);
    const MeshTopology topology(static_cast<int>(c.sample.points.cols()), c.sample.triangles);
    EXPECT_EQ(topology.eulerCharacteristic(), c.sample.euler_characteristic);
    EXPECT_EQ(topology.counts().connected_components, 1);
    EXPECT_EQ(topology.counts().nonmanifold_edges, 0);
    EXPECT_TRUE(topology.counts().consistently_oriented);
  }
}

// Face normals of a fine mesh agree in sign with the exact normals (the winding is outward).
TEST(AnalyticSurfaces, TriangleWindingFollowsTheNormal) {
  for (const Case& c : allSurfaces(0.0)) {
    SCOPED_TRACE(c.name);
    const SurfaceSample& s = c.sample;
    for (Eigen::Index t = 0; t < s.triangles.cols(); ++t) {
      const Eigen::Vector3d a = s.points.col(s.triangles(0, t)),
                            b = s.points.col(s.triangles(1, t)),
                            d = s.points.col(s.triangles(2, t));
      ASSERT_GT((b - a).cross(d - a).dot(s.normals.col(s.triangles(0, t))), 0.0);
    }
  }
}

// Gauss-Bonnet for the exact curvature: closed surfaces give 2 pi chi; the paraboloid and the
// saddle over [-1,1]^2 are checked against the boundary term of their square rim independently:
// for the paraboloid the total curvature is 2 pi minus the rim's total geodesic curvature, which
// is positive but below 2 pi; for the saddle it is negative.
TEST(AnalyticSurfaces, GaussBonnetOfExactCurvature) {
  EXPECT_NEAR(makeIcosphere(2).total_gauss_curvature, 4 * kPi, 1e-12);
  EXPECT_NEAR(makeTorus({16, 0.0, 1}).total_gauss_curvature, 0.0, 1e-12);
  const SurfaceSample paraboloid = makeParaboloid({8, 0.0, 1});
  EXPECT_GT(paraboloid.total_gauss_curvature, 0.0);
  EXPECT_LT(paraboloid.total_gauss_curvature, 2 * kPi);
  EXPECT_LT(makeSaddle({8, 0.0, 1}).total_gauss_curvature, 0.0);
  // The area of z = (x^2 + y^2) / 2 over [-1, 1]^2, the integral of sqrt(1 + x^2 + y^2): in y in
  // closed form, int_0^1 sqrt(c^2 + y^2) dy = (sqrt(c^2 + 1) + c^2 asinh(1 / c)) / 2 with
  // c^2 = 1 + x^2, then in x by Simpson's rule (error ~1e-14 at 2,000 intervals). The generator
  // integrates with a 2D midpoint rule of 1,000^2 cells: O(h^2), about 1e-7.
  const auto inner = [](double x) {
    const double c2 = 1.0 + x * x;
    return 0.5 * (std::sqrt(c2 + 1.0) + c2 * std::asinh(1.0 / std::sqrt(c2)));
  };
  const int intervals = 2000;
  double simpson = inner(0.0) + inner(1.0);
  for (int i = 1; i < intervals; ++i) simpson += (i % 2 ? 4.0 : 2.0) * inner(double(i) / intervals);
  const double exact_area = 4.0 * simpson / (3.0 * intervals);
  EXPECT_NEAR(paraboloid.area, exact_area, 1e-6 * exact_area);
  EXPECT_GT(exact_area, 4.0 * 1.1);  // far from the flat square's 4: the curvature counts
}

// On a regular periodic torus grid the trapezoid rule is spectrally accurate: sum K dA = 0 and
// sum dA = 4 pi^2 R r to round-off, which checks K and the area element together.
TEST(AnalyticSurfaces, TorusQuadratureOfExactCurvature) {
  const SurfaceSample torus = makeTorus({64, 0.0, 1});
  const int nu = 64, nv = 32;
  const double du = 2 * kPi / nu, dv = 2 * kPi / nv;
  double area = 0.0, total_k = 0.0;
  for (int j = 0; j < nv; ++j) {
    const double v = j * dv;
    const double element = (1.0 + 0.4 * std::cos(v)) * 0.4 * du * dv;
    for (int i = 0; i < nu; ++i) {
      area += element;
      total_k += torus.gauss_curvature[j * nu + i] * element;
    }
  }
  EXPECT_NEAR(area, torus.area, 1e-12);
  EXPECT_NEAR(total_k, 0.0, 1e-12);
}

TEST(AnalyticSurfaces, RigidMotionMovesEveryQuantity) {
  SurfaceSample torus = makeTorus({16, 0.08, 3});
  const SurfaceSample original = torus;
  torus.rotateAndShiftFar();
  EXPECT_GT(torus.points.col(0).norm(), 1e5);
  for (Eigen::Index i = 0; i < torus.points.cols(); ++i) {
    ASSERT_NEAR(torus.normals.col(i).norm(), 1.0, 1e-12);
    ASSERT_NEAR(torus.normals.col(i).dot(torus.dir1.col(i)), 0.0, 1e-12);
    ASSERT_NEAR((torus.points.col(i) - torus.points.col(0)).norm(),
                (original.points.col(i) - original.points.col(0)).norm(), 1e-9);
  }
  EXPECT_EQ(torus.asCloud().triangles.cols(), 0);
  EXPECT_EQ(torus.asCloud().points.cols(), torus.points.cols());
}

TEST(AnalyticSurfaces, IcosphereLevelsHaveTheExpectedSize) {
  for (int level = 0; level <= 4; ++level) {
    EXPECT_EQ(makeIcosphere(level).points.cols(), 10 * (1 << (2 * level)) + 2);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
