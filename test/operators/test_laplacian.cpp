// The Laplacians' entries against a hand-computed triangle pair and the reference assembly
// (reference_operators.h), the scale on a sphere, and their identities: L 1 = 0, symmetry,
// negative semi-definiteness, one zero eigenvalue per component, linear precision of the cotangent
// weights, averaged = M^-1 summed.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "analytic_surfaces.h"
#include "data_catalogue.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/laplacian.h"
#include "reference_operators.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

struct Mesh {
  const char* name;
  Eigen::Matrix3Xd points;
  MeshTopology topology;
};

Mesh fromSample(const char* name, const SurfaceSample& s) {
  return {name, s.points, MeshTopology(static_cast<int>(s.points.cols()), s.triangles)};
}

Mesh fromFile(const char* name, const std::string& path) {
  const pcl::PolygonMesh m = loadMesh(path);
  return {name, vertexPositions(m.cloud), MeshTopology(m)};
}

std::vector<Mesh> testMeshes() {
  std::vector<Mesh> meshes;
  meshes.push_back(
      fromSample("jittered torus far away", makeTorus({24, 0.1, 5}).rotateAndShiftFar()));
  meshes.push_back(fromSample("jittered sphere", makeIcosphere(2, 2.0, 0.1)));
  meshes.push_back(fromSample("saddle (boundary)", makeSaddle({12, 0.1, 2})));
  meshes.push_back(fromFile("bun_zipper_res4 (non-manifold, duplicates)",
                            sharedData("meshes/bun_zipper_res4.ply")));
  meshes.push_back(
      fromFile("bun_zipper_res3 (unused vertices)", sharedData("meshes/bun_zipper_res3.ply")));
  return meshes;
}

// Largest entry of |a - b| over the largest entry of |b|.
double relativeDifference(const Eigen::SparseMatrix<double>& a,
                          const Eigen::SparseMatrix<double>& b) {
  const Eigen::SparseMatrix<double> difference = a - b;
  return difference.coeffs().cwiseAbs().maxCoeff() / b.coeffs().cwiseAbs().maxCoeff();
}

// Two acute triangles ABC (in z = 0) and ADB (D above the plane) sharing the edge AB. By hand:
//   ABC: cot A = 1/2, cot B = 1, cot C = 1/3 (dot / |cross| = 3/6, 6/6, 2/6); area 3.
//   ADB: cot A = cot B = 4.5 / (3 sqrt 10), cot D = 7.75 / (3 sqrt 10); area 1.5 sqrt 10.
struct TrianglePair {
  Eigen::Matrix3Xd points = (Eigen::Matrix3Xd(3, 4) << 0, 3, 1, 1.5,  //
                             0, 0, 2, -3,                             //
                             0, 0, 0, 1)
                                .finished();
  MeshTopology topology{4, (Eigen::Matrix3Xi(3, 2) << 0, 0, 1, 3, 2, 1).finished()};
  static constexpr int A = 0, B = 1, C = 2, D = 3;
};

TEST(Laplacian, CotangentEntriesOfAHandComputedTrianglePair) {
  const TrianglePair pair;
  const double root10 = std::sqrt(10.0);
  const double cot_d = 7.75 / (3 * root10), cot_ab_in_abd = 4.5 / (3 * root10);
  Eigen::Matrix4d expected = Eigen::Matrix4d::Zero();
  const auto edge = [&expected](int i, int j, double w) { expected(i, j) = expected(j, i) = w; };
  edge(TrianglePair::A, TrianglePair::B, 0.5 * (1.0 / 3.0 + cot_d));  // interior: two cotangents
  edge(TrianglePair::A, TrianglePair::C, 0.5 * 1.0);                  // boundary edges: one
  edge(TrianglePair::B, TrianglePair::C, 0.5 * 0.5);
  edge(TrianglePair::A, TrianglePair::D, 0.5 * cot_ab_in_abd);
  edge(TrianglePair::B, TrianglePair::D, 0.5 * cot_ab_in_abd);
  for (int i = 0; i < 4; ++i) expected(i, i) = -expected.row(i).sum();
  for (const Eigen::SparseMatrix<double>& l :
       {laplacian(pair.topology, pair.points), cotangentLaplacian(pair.topology, pair.points)}) {
    EXPECT_LT((Eigen::MatrixXd(l) - expected).cwiseAbs().maxCoeff(), 1e-15) << Eigen::MatrixXd(l);
  }
  // Mixed Voronoi masses by hand (both triangles acute: the Voronoi cells,
  // (|e_ij|^2 cot k + |e_ik|^2 cot j) / 8 per corner i): M^-1 L row by row.
  const double abd_ab = (9 * cot_d + 12.25 * cot_ab_in_abd) / 8;
  const Eigen::Vector4d mass(1.0 + abd_ab, 7.0 / 8 + abd_ab, 9.0 / 8, 24.5 * cot_ab_in_abd / 8);
  const Eigen::MatrixXd averaged = Eigen::MatrixXd(
      laplacian(pair.topology, pair.points, LaplacianWeights::Cotangent, LaplacianForm::Averaged));
  EXPECT_LT((averaged - mass.cwiseInverse().asDiagonal() * expected).cwiseAbs().maxCoeff(), 1e-15);
  // Uniform: the graph, whatever the geometry.
  Eigen::Matrix4d graph;
  graph << -3, 1, 1, 1,  //
      1, -3, 1, 1,       //
      1, 1, -2, 0,       //
      1, 1, 0, -2;
  EXPECT_EQ(Eigen::MatrixXd(laplacian(pair.topology, pair.points, LaplacianWeights::Uniform)),
            Eigen::MatrixXd(graph));
}

// On a sphere of radius r, x_i . (x_i - x_j) = |x_i - x_j|^2 / 2 for any inscribed mesh, so
// n_i . (L x)_i = -sum_j w_ij |e_ij|^2 / (2 r) = -2 H A_i with H = 1 / r and A_i the (signed)
// circumcentric Voronoi area: an exact identity that fixes the scale of the weights, on jittered
// triangles (some obtuse) too.
TEST(Laplacian, NormalPartOfLxOnAnInscribedMeshIsMinusTwoHTimesTheVoronoiArea) {
  const double radius = 2.0;
  const SurfaceSample sphere = makeIcosphere(3, radius, 0.2);
  const MeshTopology t(static_cast<int>(sphere.points.cols()), sphere.triangles);
  const Eigen::Matrix3Xd lx = sphere.points * laplacian(t, sphere.points);  // symmetric L
  const Eigen::VectorXd voronoi = referenceMass(t, sphere.points, MassType::Voronoi);
  // The jitter makes obtuse triangles, where Voronoi and mixed cells differ.
  ASSERT_GT((voronoi - referenceMass(t, sphere.points)).cwiseAbs().maxCoeff(), 1e-3);
  double worst = 0.0;
  for (int v = 0; v < t.numVertices(); ++v) {
    const double normal_part = sphere.points.col(v).dot(lx.col(v)) / radius;
    worst = std::max(worst, std::abs(normal_part + 2.0 / radius * voronoi[v]));
  }
  std::printf("n . L x + 2 H A: max %.2e (mean area %.2e)\n", worst, voronoi.mean());
  EXPECT_LT(worst, 1e-14 * radius * radius);
}

// The reference assembly, scattered from each triangle (reference_operators.h), against the
// library's gather: the reference that the smoothing tests use is the library's operator.
TEST(Laplacian, TheReferenceAssemblyIsTheLibrarysCotangentLaplacian) {
  for (const Mesh& m : testMeshes()) {
    SCOPED_TRACE(m.name);
    const double difference = relativeDifference(laplacian(m.topology, m.points),
                                                 referenceCotangentLaplacian(m.topology, m.points));
    std::printf("%s: reference L differs by %.2e relative\n", m.name, difference);
    EXPECT_LT(difference, 1e-12);
  }
}

TEST(Laplacian, RowsSumToZeroAndSummedFormIsSymmetric) {
  for (const Mesh& m : testMeshes()) {
    SCOPED_TRACE(m.name);
    for (auto w : {LaplacianWeights::Uniform, LaplacianWeights::Cotangent}) {
      const Eigen::SparseMatrix<double> l = laplacian(m.topology, m.points, w);
      const Eigen::VectorXd ones = Eigen::VectorXd::Ones(l.cols());
      EXPECT_LT((l * ones).cwiseAbs().maxCoeff(), 1e-12 * l.cwiseAbs().sum() / l.cols() + 1e-300);
      const Eigen::SparseMatrix<double> transpose = l.transpose();
      EXPECT_LT((l - transpose).cwiseAbs().sum(), 1e-14 * l.cwiseAbs().sum());
      const Eigen::SparseMatrix<double> averaged =
          laplacian(m.topology, m.points, w, LaplacianForm::Averaged);
      EXPECT_LT((averaged * ones).cwiseAbs().maxCoeff(),
                1e-9 * averaged.cwiseAbs().sum() / l.cols());
    }
  }
}

// Both ends of an edge add the same cotangents in the same order, so the summed L is its own
// transpose bit for bit, and its compressed rows (what the Python module hands scipy as CSR) are
// the same matrix as its compressed columns, for both weights and forms: on every shared mesh,
// with its boundaries, non-manifold edges and duplicate faces.
TEST(Laplacian, SummedIsItsOwnTransposeBitForBitAndRowStorageIsTheSameMatrix) {
  const auto same = [](const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
    return a.nonZeros() == b.nonZeros() &&
           std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1,
                      b.outerIndexPtr()) &&
           std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr()) &&
           std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr());
  };
  int meshes = 0;
  for (const SharedMesh& row : sharedMeshes()) {
    SCOPED_TRACE(row.path);
    const MeshFile file = readMeshFile(sharedData(row.path));
    ASSERT_TRUE(file.positions.allFinite());
    const MeshTopology topology(file.mesh, OutOfRangeFacePolicy::Drop);
    for (auto w : {LaplacianWeights::Uniform, LaplacianWeights::Cotangent}) {
      for (auto form : {LaplacianForm::Summed, LaplacianForm::Averaged}) {
        const Eigen::SparseMatrix<double> columns = laplacian(topology, file.positions, w, form);
        // Eigen's conversion between storage orders is a transposition by counting.
        const Eigen::SparseMatrix<double> rows =
            laplacian<Eigen::RowMajor>(topology, file.positions, w, form);
        EXPECT_TRUE(same(rows, columns)) << static_cast<int>(w) << " " << static_cast<int>(form);
        if (form == LaplacianForm::Summed) {
          const Eigen::SparseMatrix<double> transpose = columns.transpose();
          EXPECT_TRUE(same(transpose, columns)) << static_cast<int>(w);
        }
      }
    }
    ++meshes;
  }
  EXPECT_EQ(meshes, static_cast<int>(sharedMeshes().size()));
}

TEST(Laplacian, UniformWeightsAreTheGraph) {
  const SurfaceSample torus = makeTorus({12, 0.0, 1});
  const MeshTopology t(static_cast<int>(torus.points.cols()), torus.triangles);
  const Eigen::SparseMatrix<double> l = laplacian(t, torus.points, LaplacianWeights::Uniform);
  for (int v = 0; v < t.numVertices(); ++v) {
    EXPECT_EQ(l.coeff(v, v), -6.0);
    for (const int w : t.neighbours(v)) EXPECT_EQ(l.coeff(v, w), 1.0);
  }
  EXPECT_EQ(l.nonZeros(), t.numVertices() * 7);
}

// Dense eigenvalues of small meshes: all <= 0, and exactly one (near) zero per component.
TEST(Laplacian, NegativeSemiDefiniteWithOneZeroEigenvaluePerComponent) {
  // Two separate jittered spheres and a saddle: three components.
  const SurfaceSample a = makeIcosphere(1, 1.0, 0.08), b = makeIcosphere(1, 0.5, 0.08, 9);
  const SurfaceSample c = makeSaddle({5, 0.08, 3});
  Eigen::Matrix3Xd points(3, a.points.cols() + b.points.cols() + c.points.cols());
  points << a.points, (b.points.colwise() + Eigen::Vector3d(5, 0, 0)),
      (c.points.colwise() + Eigen::Vector3d(0, 5, 0));
  Eigen::Matrix3Xi tris(3, a.triangles.cols() + b.triangles.cols() + c.triangles.cols());
  const int nb = static_cast<int>(a.points.cols()), nc = nb + static_cast<int>(b.points.cols());
  tris << a.triangles, (b.triangles.array() + nb).matrix(), (c.triangles.array() + nc).matrix();
  const MeshTopology t(static_cast<int>(points.cols()), tris);
  ASSERT_EQ(t.counts().connected_components, 3);
  for (auto w : {LaplacianWeights::Uniform, LaplacianWeights::Cotangent}) {
    const Eigen::MatrixXd dense = Eigen::MatrixXd(laplacian(t, points, w));
    const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues();
    const double scale = eig.cwiseAbs().maxCoeff();
    EXPECT_LT(eig.maxCoeff(), 1e-12 * scale);
    int zeros = 0;
    for (Eigen::Index i = 0; i < eig.size(); ++i) zeros += std::abs(eig[i]) < 1e-10 * scale;
    EXPECT_EQ(zeros, 3);
  }
}

// Largest interior row of L x (x centred, so the test measures L and not the coordinates' size).
double worstInteriorRow(const MeshTopology& t, const Eigen::Matrix3Xd& points, LaplacianWeights w) {
  const Eigen::Matrix3Xd local = points.colwise() - points.rowwise().mean();
  const Eigen::Matrix3Xd lx = local * laplacian(t, points, w);  // symmetric L
  double worst = 0.0;
  for (int v = 0; v < t.numVertices(); ++v) {
    if (!t.isBoundary(v)) worst = std::max(worst, lx.col(v).norm());
  }
  return worst;
}

// Cotangent weights reproduce linear functions: interior rows of L x vanish on any planar mesh,
// however irregular (here a strongly jittered, rotated patch).
TEST(Laplacian, CotangentLinearPrecisionOnIrregularPlanarPatch) {
  SurfaceSample plane = makePlane({20, 0.1, 11});
  Eigen::Isometry3d rotation = Eigen::Isometry3d::Identity();
  rotation.linear() =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(3, -1, 2).normalized()).toRotationMatrix();
  plane.transform(rotation);
  const MeshTopology t(static_cast<int>(plane.points.cols()), plane.triangles);
  EXPECT_LT(worstInteriorRow(t, plane.points, LaplacianWeights::Cotangent), 1e-12);
  // The uniform Laplacian has no such property on an irregular mesh.
  EXPECT_GT(worstInteriorRow(t, plane.points, LaplacianWeights::Uniform), 1e-3);
  // 1e5 from the origin the coordinates themselves are only planar to their rounding (ulp
  // 1.5e-11): L x stays at that level.
  plane.rotateAndShiftFar();
  EXPECT_LT(worstInteriorRow(t, plane.points, LaplacianWeights::Cotangent), 1e-9);
}

TEST(Laplacian, AveragedIsSummedDividedByMass) {
  const SurfaceSample s = makeIcosphere(2, 1.0, 0.1);
  const MeshTopology t(static_cast<int>(s.points.cols()), s.triangles);
  const Eigen::SparseMatrix<double> summed = referenceCotangentLaplacian(t, s.points);
  for (auto mass : {MassType::Barycentric, MassType::Voronoi, MassType::MixedVoronoi}) {
    const Eigen::VectorXd m = referenceMass(t, s.points, mass);
    const Eigen::SparseMatrix<double> averaged =
        laplacian(t, s.points, LaplacianWeights::Cotangent, LaplacianForm::Averaged, mass);
    const Eigen::SparseMatrix<double> expected = m.cwiseInverse().asDiagonal() * summed;
    EXPECT_LT(relativeDifference(averaged, expected), 1e-12);
  }
}

TEST(Laplacian, DegenerateFaceLeavesEveryOtherRowFinite) {
  // A square fan with one zero-area sliver (vertex 5 on the segment 0-1) and an isolated vertex.
  Eigen::Matrix3Xd p(3, 7);
  p << 0, 1, 1, 0, 0.5, 0.5, 9,  //
      0, 0, 1, 1, 0.5, 0, 9,     //
      0, 0, 0, 0, 0.1, 0, 9;
  Eigen::Matrix3Xi tris(3, 5);
  tris << 0, 1, 2, 3, 0, 1, 2, 3, 0, 5, 4, 4, 4, 4, 1;
  const MeshTopology topology(7, tris);
  for (auto w : {LaplacianWeights::Uniform, LaplacianWeights::Cotangent}) {
    for (auto f : {LaplacianForm::Summed, LaplacianForm::Averaged}) {
      const Eigen::SparseMatrix<double> l = laplacian(topology, p, w, f);
      EXPECT_TRUE(Eigen::MatrixXd(l).allFinite());
      EXPECT_EQ(Eigen::MatrixXd(l).row(6).cwiseAbs().sum(), 0.0);  // isolated vertex: empty row
    }
  }
  const Eigen::SparseMatrix<double> cot = laplacian(topology, p);
  EXPECT_EQ(cot.coeff(0, 5), 0.0);  // only the sliver holds edge 0-5: zero weight
}

TEST(Laplacian, RejectsNonFiniteAndMismatchedPositions) {
  const SurfaceSample s = makeIcosphere(1);
  const MeshTopology t(static_cast<int>(s.points.cols()), s.triangles);
  Eigen::Matrix3Xd bad = s.points;
  bad(1, 7) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(laplacian(t, bad), InvalidMeshException);
  EXPECT_THROW(laplacian(t, s.points.leftCols(5)), InvalidMeshException);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
