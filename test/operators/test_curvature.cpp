// Curvatures against exact values, Gauss-Bonnet, and the convergence orders of docs/accuracy.md.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/curvature.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Errors {
  double max = 0.0, rms = 0.0;
};

Errors errors(const Eigen::VectorXd& value, const Eigen::VectorXd& exact) {
  const Eigen::VectorXd d = value - exact;
  return {d.cwiseAbs().maxCoeff(), std::sqrt(d.squaredNorm() / static_cast<double>(d.size()))};
}

// Integrated Gaussian curvature as computeCurvatures() gives it (the K the tools write, times the
// vertex area), with the number of vertices whose K is not finite.
struct IntegratedK {
  double sum = 0.0;
  int nonfinite = 0;
};

IntegratedK integratedGaussCurvature(const VertexCurvatures& c) {
  IntegratedK total;
  for (Eigen::Index v = 0; v < c.gauss_curvature.size(); ++v) {
    const double k_area = c.gauss_curvature[v] * c.vertex_area[v];
    if (std::isfinite(k_area)) {
      total.sum += k_area;
    } else {
      ++total.nonfinite;
    }
  }
  return total;
}

// Gauss-Bonnet with a boundary, sum of K dA + the boundary's geodesic turning = 2 pi chi: the
// angle defect pi - sum of angles of a boundary vertex is its turning, so both the angle defect
// and computeCurvatures' K times the vertex area sum to 2 pi chi on open meshes as on closed ones,
// for every mass type (chi of the sampled surface, not of the mesh).
TEST(Curvature, GaussBonnetOnAnalyticMeshesOpenAndClosed) {
  for (const SurfaceSample& s :
       {makeIcosphere(3, 2.0, 0.1), makeTorus({40, 0.1, 1}).rotateAndShiftFar(),
        makeCylinder({24, 0.1, 2}), makeSaddle({16, 0.1, 3}), makePlane({8, 0.1, 4}),
        makeParaboloid({16, 0.0, 1}), makeSaddle({12, 0.2, 5}).rotateAndShiftFar()}) {
    const MeshTopology t = topologyOf(s);
    const double expected = 2 * kPi * s.euler_characteristic;
    const Eigen::VectorXd defect = angleDefect(t, s.points);
    EXPECT_NEAR(defect.sum(), expected, 1e-9);
    // Vertex by vertex too, K dA = the defect (the sum alone would not see an angle taken at
    // another corner of each triangle: its three angles still add up once).
    const VertexCurvatures c = computeCurvatures(t, s.points);
    for (int v = 0; v < t.numVertices(); ++v) {
      ASSERT_NEAR(defect[v], c.gauss_curvature[v] * c.vertex_area[v],
                  1e-12 * (1 + std::abs(defect[v])))
          << "vertex " << v;
    }
    for (auto mass : {MassType::MixedVoronoi, MassType::Barycentric}) {
      const IntegratedK k = integratedGaussCurvature(computeCurvatures(t, s.points, mass));
      EXPECT_EQ(k.nonfinite, 0);
      EXPECT_NEAR(k.sum, expected, 1e-9) << "chi " << s.euler_characteristic;
    }
  }
}

// A planar square patch, regular or jittered (its border rows stay on the border): every interior
// vertex and every vertex inside a border side has angle sum 2 pi or pi, each of the four corners
// pi / 2, so K dA is pi / 2 at the corners and 0 elsewhere; by hand, whatever the triangulation.
TEST(Curvature, IntegratedGaussCurvatureOfAPlanarPatchIsItsCornersTurning) {
  for (const double jitter : {0.0, 0.2}) {
    SurfaceSample plane = makePlane({8, jitter, 6});
    const MeshTopology t = topologyOf(plane);
    const VertexCurvatures c = computeCurvatures(t, plane.points);
    int corners = 0;
    for (int v = 0; v < t.numVertices(); ++v) {
      const bool corner =
          std::abs(plane.points(0, v)) == 1.0 && std::abs(plane.points(1, v)) == 1.0;
      corners += corner;
      EXPECT_NEAR(c.gauss_curvature[v] * c.vertex_area[v], corner ? kPi / 2 : 0.0, 1e-14)
          << "vertex " << v << " at " << plane.points.col(v).transpose();
    }
    EXPECT_EQ(corners, 4);
  }
}

TEST(Curvature, GaussBonnetOnRealScans) {
  // Open scans (bun_zipper, tum_rabbit, bun045) included: computeCurvatures' K times the vertex
  // area, not only the angle defect, must sum to 2 pi chi there.
  int skipped = 0;
  for (const char* file :
       {"meshes/bumpy.off", "meshes/bunny.off", "meshes/cow.off", "meshes/horse.ply",
        "meshes/igea.ply", "meshes/rocker-arm.off", "meshes/tum_rabbit.vtk",
        "meshes/bun_zipper.ply", "meshes/bun045_rangegrid_tri.ply"}) {
    SCOPED_TRACE(file);
    const pcl::PolygonMesh mesh = loadMesh(sharedData(file));
    const MeshTopology t(mesh);
    if (t.counts().nonmanifold_vertices > 0) {
      // A bow-tie vertex is one vertex for chi but two fans for the angle sums: each extra fan
      // adds 2 pi (closed fan) or pi (open) of defect that chi does not see. Counted below.
      ++skipped;
      continue;
    }
    const Eigen::Matrix3Xd x = vertexPositions(mesh.cloud);
    const double expected = 2 * kPi * t.eulerCharacteristic();
    EXPECT_NEAR(angleDefect(t, x).sum(), expected, 1e-8);
    const IntegratedK k = integratedGaussCurvature(computeCurvatures(t, x));
    // Only unreferenced vertices have no area (and a NaN K) on these scans.
    EXPECT_EQ(k.nonfinite, t.counts().unreferenced_vertices);
    EXPECT_NEAR(k.sum, expected, 1e-8);
  }
  // Exactly one scan has bow-tie vertices: bun045_rangegrid_tri.ply, a raw range grid (CATALOG.md).
  EXPECT_EQ(skipped, 1);
}

// docs/accuracy.md: unit icosphere, mixed Voronoi: max |K - 1| 8.9e-5 at level 6, order 2; and
// n . (-M^-1 L x) / 2 = 1 exactly with the exact normal n on any sphere-inscribed mesh (because
// x_i . (x_i - x_j) = |x_i - x_j|^2 / 2 turns the normal part of L x into the Voronoi area).
// Our H = |M^-1 L x| / 2 also holds the small tangential part of L x, so it converges at order 2
// instead of being exact.
TEST(Curvature, IcosphereConvergesAtOrderTwo) {
  Errors previous_k, previous_h;
  for (int level = 1; level <= 6; ++level) {
    const SurfaceSample s = makeIcosphere(level);
    const MeshTopology t = topologyOf(s);
    const VertexCurvatures c = computeCurvatures(t, s.points);
    const Errors k = errors(c.gauss_curvature, s.gauss_curvature),
                 h = errors(c.mean_curvature, s.mean_curvature);
    const Eigen::Matrix3Xd hn = meanCurvatureNormal(t, s.points);
    const Eigen::VectorXd projected = (hn.cwiseProduct(s.normals)).colwise().sum().transpose();
    const Errors exact = errors(projected, s.mean_curvature);
    std::printf(
        "icosphere level %d (%ld V): K max %.2e rms %.2e | H max %.2e rms %.2e | "
        "n.Hn max %.2e rms %.2e\n",
        level, static_cast<long>(s.points.cols()), k.max, k.rms, h.max, h.rms, exact.max,
        exact.rms);
    EXPECT_LT(exact.max, 3e-12);  // docs/accuracy.md: 1.4e-12
    if (level >= 3) {
      EXPECT_NEAR(std::log2(previous_k.max / k.max), 2.0, 0.25) << "level " << level;
      EXPECT_NEAR(std::log2(previous_h.max / h.max), 2.0, 0.25) << "level " << level;
    }
    if (level == 6) {
      EXPECT_LT(k.max, 9.0e-5);
      EXPECT_LT(k.rms, 7.6e-5);
    }
    previous_k = k;
    previous_h = h;
  }
}

// Barycentric areas make K inconsistent: the error does not decrease (documented behaviour).
TEST(Curvature, BarycentricAreaDoesNotConverge) {
  const SurfaceSample coarse = makeIcosphere(4), fine = makeIcosphere(6);
  const double e4 =
      errors(computeCurvatures(topologyOf(coarse), coarse.points, MassType::Barycentric)
                 .gauss_curvature,
             coarse.gauss_curvature)
          .max;
  const double e6 =
      errors(
          computeCurvatures(topologyOf(fine), fine.points, MassType::Barycentric).gauss_curvature,
          fine.gauss_curvature)
          .max;
  std::printf("barycentric K error: level 4 %.3f, level 6 %.3f\n", e4, e6);
  EXPECT_GT(e6, 0.1);
  EXPECT_GT(e6, 0.8 * e4);
}

// docs/accuracy.md: regular torus R=1, r=0.4 at 131,072 V: max |K-K*| 2.7e-4, max |H-H*| 5.2e-5,
// both order 2.
TEST(Curvature, RegularTorusConvergesAtOrderTwo) {
  Errors previous_k, previous_h;
  for (int resolution : {64, 128, 256, 512}) {
    const SurfaceSample s = makeTorus({resolution, 0.0, 1});
    const VertexCurvatures c = computeCurvatures(topologyOf(s), s.points);
    const Errors k = errors(c.gauss_curvature, s.gauss_curvature),
                 h = errors(c.mean_curvature, s.mean_curvature);
    std::printf("torus %ld V: K max %.2e rms %.2e  H max %.2e rms %.2e\n",
                static_cast<long>(s.points.cols()), k.max, k.rms, h.max, h.rms);
    if (resolution > 64) {
      EXPECT_NEAR(std::log2(previous_k.max / k.max), 2.0, 0.2);
      EXPECT_NEAR(std::log2(previous_h.max / h.max), 2.0, 0.2);
    }
    if (resolution == 512) {
      EXPECT_LT(k.max, 2.8e-4);
      EXPECT_LT(k.rms, 1.2e-4);
      EXPECT_LT(h.max, 5.3e-5);
      EXPECT_LT(h.rms, 2.7e-5);
    }
    previous_k = k;
    previous_h = h;
  }
}

// The mesh operators form differences of positions, exact in double wherever the mesh lies: a
// torus (on a 2^-20 grid, so that the move is exact) at a survey's place has the curvatures it has
// at the origin, to 1e-9 relative.
TEST(Curvature, ATorusFarFromTheOriginHasItsCurvaturesAtTheOrigin) {
  SurfaceSample s = makeTorus({128, 0.0, 1});
  s.points = s.points.unaryExpr([](double v) { return std::round(v * 1048576.0) / 1048576.0; });
  const MeshTopology topology = topologyOf(s);
  const VertexCurvatures here = computeCurvatures(topology, s.points);
  const VertexCurvatures there =
      computeCurvatures(topology, s.points.colwise() + Eigen::Vector3d(5e5, 5e6, 200.0));
  const auto relative = [](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return (a - b).cwiseAbs().maxCoeff() / a.cwiseAbs().maxCoeff();
  };
  EXPECT_LE(relative(here.mean_curvature, there.mean_curvature), 1e-9);
  EXPECT_LE(relative(here.gauss_curvature, there.gauss_curvature), 1e-9);
  EXPECT_LE(relative(here.k1, there.k1), 1e-9);
  EXPECT_LE(relative(here.k2, there.k2), 1e-9);
}

// On irregular (scan-like) meshes the pointwise cotangent curvatures do not converge: with 0.1h
// jitter the error stays at the level docs/accuracy.md measured (documented, not a failure).
TEST(Curvature, JitteredMeshesDoNotConvergePointwise) {
  const SurfaceSample coarse = makeIcosphere(4, 1.0, 0.1), fine = makeIcosphere(6, 1.0, 0.1);
  const VertexCurvatures cc = computeCurvatures(topologyOf(coarse), coarse.points);
  const VertexCurvatures cf = computeCurvatures(topologyOf(fine), fine.points);
  const Errors kc = errors(cc.gauss_curvature, coarse.gauss_curvature),
               kf = errors(cf.gauss_curvature, fine.gauss_curvature);
  const Errors hf = errors(cf.mean_curvature, fine.mean_curvature);
  std::printf("jittered icosphere: K rms level 4 %.2e, level 6 %.2e; H rms level 6 %.2e\n", kc.rms,
              kf.rms, hf.rms);
  // docs/accuracy.md measured K rms 1.0e-2 and max 0.286 at level 6: no decrease worth the name
  // with 16x the vertices, and an error of that size.
  EXPECT_GT(kf.rms, 0.5 * kc.rms);
  EXPECT_GT(kf.rms, 3e-3);
  EXPECT_LT(kf.rms, 3e-2);
  EXPECT_GT(hf.rms, 3e-3);
  const SurfaceSample torus_c = makeTorus({128, 0.1, 3}), torus_f = makeTorus({512, 0.1, 3});
  const Errors tc = errors(computeCurvatures(topologyOf(torus_c), torus_c.points).mean_curvature,
                           torus_c.mean_curvature);
  const Errors tf = errors(computeCurvatures(topologyOf(torus_f), torus_f.points).mean_curvature,
                           torus_f.mean_curvature);
  std::printf("jittered torus: H rms %.2e -> %.2e\n", tc.rms, tf.rms);
  EXPECT_GT(tf.rms, 0.5 * tc.rms);
  EXPECT_NEAR(tf.rms, 0.071, 0.02);  // docs/accuracy.md: 0.071 at 131,072 V
}

TEST(Curvature, PrincipalCurvaturesOfCylinderAndSphere) {
  const SurfaceSample cylinder = makeCylinder({96, 0.0, 1}, 1.0, 2.0);
  const MeshTopology t = topologyOf(cylinder);
  const VertexCurvatures c = computeCurvatures(t, cylinder.points);
  for (int v = 0; v < t.numVertices(); ++v) {
    // The mesh is made of planar rectangles (rings at the same angles), so every angle sum is
    // 2 pi inside and pi on the rims: K = 0 everywhere, the rims included.
    EXPECT_NEAR(c.gauss_curvature[v], 0.0, 1e-12) << "vertex " << v;
    // On the rims Hn holds the rim's curvature too (curvature.h): k1, k2 only inside.
    if (t.isBoundary(v)) continue;
    EXPECT_NEAR(c.k1[v], 1.0, 2e-3);
    EXPECT_NEAR(c.k2[v], 0.0, 2e-3);
  }
  const SurfaceSample sphere = makeIcosphere(4, 3.0);
  const VertexCurvatures s = computeCurvatures(topologyOf(sphere), sphere.points);
  EXPECT_NEAR(s.k1.maxCoeff(), 1.0 / 3.0, 1e-3);
  EXPECT_NEAR(s.k2.minCoeff(), 1.0 / 3.0, 1e-3);
  EXPECT_GT(s.clamped_vertices, 0);  // umbilics: H^2 - K is round-off, often negative
}

TEST(Curvature, FlippingTheOrientationFlipsH) {
  SurfaceSample s = makeIcosphere(3, 1.0, 0.08);
  const double h_out = computeCurvatures(topologyOf(s), s.points).mean_curvature.mean();
  s.triangles.row(1).swap(s.triangles.row(2));
  const VertexCurvatures inward = computeCurvatures(topologyOf(s), s.points);
  EXPECT_GT(h_out, 0.9);
  EXPECT_NEAR(inward.mean_curvature.mean(), -h_out, 1e-12);
  EXPECT_GT(inward.gauss_curvature.minCoeff(), 0.0);  // K does not depend on orientation
}

TEST(Curvature, DegenerateAndIsolatedVerticesAreMaskedNotNaNElsewhere) {
  SurfaceSample s = makeIcosphere(2);
  // Add a sliver triangle on a new vertex placed on an edge's midpoint, and an isolated vertex.
  const int a = s.triangles(0, 0), b = s.triangles(1, 0);
  Eigen::Matrix3Xd p(3, s.points.cols() + 2);
  p << s.points, 0.5 * (s.points.col(a) + s.points.col(b)), Eigen::Vector3d(5, 5, 5);
  Eigen::Matrix3Xi tris(3, s.triangles.cols() + 1);
  tris << s.triangles, Eigen::Vector3i(a, static_cast<int>(s.points.cols()), b);
  const MeshTopology t(static_cast<int>(p.cols()), tris);
  const VertexCurvatures c = computeCurvatures(t, p);
  EXPECT_EQ(c.invalid_vertices, 2);
  for (int v = 0; v < t.numVertices(); ++v) {
    EXPECT_EQ(c.valid[v] != 0,
              std::isfinite(c.mean_curvature[v]) && std::isfinite(c.gauss_curvature[v]));
  }
  EXPECT_TRUE(c.mean_curvature.head(s.points.cols()).allFinite());
  EXPECT_TRUE(c.k1.head(s.points.cols()).allFinite());
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
