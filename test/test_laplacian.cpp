// Identities of the Laplacians: L 1 = 0, symmetry, negative semi-definiteness, one zero
// eigenvalue per component, linear precision of the cotangent weights, averaged = M^-1 summed.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "analytic_surfaces.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/laplacian.h"
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
  for (auto mass : {MassType::Barycentric, MassType::Voronoi, MassType::MixedVoronoi}) {
    const Eigen::VectorXd m = lumpedMass(t, s.points, mass);
    const Eigen::SparseMatrix<double> summed = laplacian(t, s.points);
    const Eigen::SparseMatrix<double> averaged =
        laplacian(t, s.points, LaplacianWeights::Cotangent, LaplacianForm::Averaged, mass);
    const Eigen::SparseMatrix<double> expected = m.cwiseInverse().asDiagonal() * summed;
    EXPECT_LT((averaged - expected).cwiseAbs().sum(), 1e-12 * expected.cwiseAbs().sum());
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
