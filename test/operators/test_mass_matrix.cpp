// Lumped masses: per-vertex cells of hand-computed triangles and of a regular grid, the reference
// assembly (reference_operators.h), the sparse matrix; each type sums to the mesh area; mixed
// Voronoi is non-negative where Voronoi is not.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "analytic_surfaces.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "reference_operators.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

double meshArea(const SurfaceSample& s) {
  double area = 0.0;
  for (Eigen::Index t = 0; t < s.triangles.cols(); ++t) {
    const Eigen::Vector3d a = s.points.col(s.triangles(0, t)), b = s.points.col(s.triangles(1, t)),
                          c = s.points.col(s.triangles(2, t));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

// The obtuse triangle A (0,0,0), B (4,0,0), C (1,1,0) (area 2, obtuse at C) and the acute pair of
// test_laplacian (ABC' in z = 0, ADB' with D above it). Cells by hand from the cotangents
// (cot A = 1, cot B = 3, cot C = -1/2 here), (|e_ij|^2 cot k + |e_ik|^2 cot j) / 8 per corner i:
// Voronoi A = (16 (-1/2) + 2 * 3) / 8 = -1/4 (the circumcentre lies beyond AB), B = 1/4, C = 2.
TEST(MassMatrix, PerVertexCellsOfHandComputedTriangles) {
  const Eigen::Matrix3Xd obtuse = (Eigen::Matrix3Xd(3, 3) << 0, 4, 1, 0, 0, 1, 0, 0, 0).finished();
  const MeshTopology one(3, (Eigen::Matrix3Xi(3, 1) << 0, 1, 2).finished());
  const auto expectCells = [](const Eigen::VectorXd& mass, const Eigen::VectorXd& cells) {
    EXPECT_LT((mass - cells).cwiseAbs().maxCoeff(), 1e-15) << mass.transpose();
  };
  expectCells(lumpedMass(one, obtuse, MassType::Voronoi), Eigen::Vector3d(-0.25, 0.25, 2));
  // Mixed: half the area to the obtuse corner, a quarter to each other.
  expectCells(lumpedMass(one, obtuse, MassType::MixedVoronoi), Eigen::Vector3d(0.5, 0.5, 1));
  expectCells(lumpedMass(one, obtuse, MassType::Barycentric), Eigen::Vector3d::Constant(2.0 / 3));

  // The acute pair: ABC' gives A 1, B' 7/8, C' 9/8; ADB' gives A and B' (9 cot D + 12.25 cot A) / 8
  // and D 24.5 cot A / 8, with cot A = cot B' = 4.5 / (3 sqrt 10), cot D = 7.75 / (3 sqrt 10).
  const Eigen::Matrix3Xd pair =
      (Eigen::Matrix3Xd(3, 4) << 0, 3, 1, 1.5, 0, 0, 2, -3, 0, 0, 0, 1).finished();
  const MeshTopology two(4, (Eigen::Matrix3Xi(3, 2) << 0, 0, 1, 3, 2, 1).finished());
  const double root10 = std::sqrt(10.0);
  const double cot_a = 4.5 / (3 * root10), cot_d = 7.75 / (3 * root10);
  const double shared = (9 * cot_d + 12.25 * cot_a) / 8;
  const Eigen::Vector4d cells(1 + shared, 7.0 / 8 + shared, 9.0 / 8, 24.5 * cot_a / 8);
  expectCells(lumpedMass(two, pair, MassType::Voronoi), cells);
  expectCells(lumpedMass(two, pair, MassType::MixedVoronoi), cells);
  const double abd = 1.5 * root10;  // area of ADB'
  expectCells(lumpedMass(two, pair, MassType::Barycentric),
              Eigen::Vector4d(1 + abd / 3, 1 + abd / 3, 1, abd / 3));

  // The sparse matrix holds these on its diagonal and nothing else.
  const Eigen::SparseMatrix<double> m = massMatrix(two, pair, MassType::Voronoi);
  ASSERT_EQ(m.rows(), 4);
  ASSERT_EQ(m.cols(), 4);
  EXPECT_EQ(m.nonZeros(), 4);
  expectCells(Eigen::MatrixXd(m).diagonal(), cells);
  EXPECT_EQ(Eigen::MatrixXd(m).cwiseAbs().sum(), Eigen::MatrixXd(m).diagonal().cwiseAbs().sum());
  EXPECT_LT((Eigen::MatrixXd(massMatrix(one, obtuse)).diagonal() - Eigen::Vector3d(0.5, 0.5, 1))
                .cwiseAbs()
                .maxCoeff(),
            1e-15)
      << "the default is mixed Voronoi";
}

// The reference cells (circumcentre polygons, scattered per triangle) against the library's
// cotangent formula gathered per vertex: the masses the smoothing tests' reference uses are the
// library's.
TEST(MassMatrix, TheReferenceCellsAreTheLibrarysMasses) {
  std::vector<std::pair<const char*, SurfaceSample>> surfaces;
  surfaces.emplace_back("jittered sphere", makeIcosphere(3, 1.0, 0.2));
  surfaces.emplace_back("jittered torus far away", makeTorus({32, 0.15, 3}).rotateAndShiftFar());
  surfaces.emplace_back("jittered saddle", makeSaddle({16, 0.15, 4}));
  for (const char* file : {"meshes/bunny.off", "meshes/bun_zipper_res3.ply"}) {
    const pcl::PolygonMesh mesh = loadMesh(sharedData(file));
    SurfaceSample scan;
    scan.points = vertexPositions(mesh.cloud);
    scan.triangles = MeshTopology(mesh).triangles();
    surfaces.emplace_back(file, scan);
  }
  for (const auto& [name, s] : surfaces) {
    const MeshTopology t(static_cast<int>(s.points.cols()), s.triangles);
    for (auto type : {MassType::Barycentric, MassType::Voronoi, MassType::MixedVoronoi}) {
      const Eigen::VectorXd reference = referenceMass(t, s.points, type);
      const double difference = (lumpedMass(t, s.points, type) - reference).cwiseAbs().maxCoeff() /
                                reference.cwiseAbs().maxCoeff();
      std::printf("%s, type %d: reference mass differs by %.2e relative\n", name,
                  static_cast<int>(type), difference);
      EXPECT_LT(difference, 1e-12) << name << ", type " << static_cast<int>(type);
    }
  }
}

TEST(MassMatrix, EveryTypeSumsToTheMeshArea) {
  for (const SurfaceSample& s : {makeIcosphere(3, 1.0, 0.1), makeTorus({32, 0.12, 3}),
                                 makeSaddle({16, 0.12, 4}).rotateAndShiftFar()}) {
    const MeshTopology t(static_cast<int>(s.points.cols()), s.triangles);
    const double area = meshArea(s);
    for (auto type : {MassType::Barycentric, MassType::Voronoi, MassType::MixedVoronoi}) {
      EXPECT_NEAR(lumpedMass(t, s.points, type).sum(), area, 1e-11 * area);
    }
  }
}

TEST(MassMatrix, MixedIsNonNegativeWhereVoronoiIsNot) {
  // A fan around vertex 0 with one very obtuse triangle: its circumcentre lies outside.
  Eigen::Matrix3Xd p(3, 4);
  p << 0, 1, -1, 0,  //
      0, 0, 0, 3,    //
      0, 0, 0.05, 0;
  Eigen::Matrix3Xi tris(3, 2);
  tris << 0, 0, 1, 3, 2, 2;  // (0,1,2) obtuse at 0, (0,3,2)
  const MeshTopology t(4, tris);
  const Eigen::VectorXd voronoi = lumpedMass(t, p, MassType::Voronoi);
  const Eigen::VectorXd mixed = lumpedMass(t, p, MassType::MixedVoronoi);
  EXPECT_LT(voronoi.minCoeff(), 0.0);
  EXPECT_GE(mixed.minCoeff(), 0.0);
  EXPECT_NEAR(mixed.sum(), voronoi.sum(), 1e-14);
}

TEST(MassMatrix, RegularGridVoronoiCellIsTheGridCell) {
  // Spacing 0.2, right triangles (their circumcentres on the hypotenuses): the Voronoi cell of a
  // grid point is the square of side 0.2 about it, cut by the border of [-1,1]^2: 0.04 inside,
  // 0.02 on an edge, 0.01 at a corner.
  const SurfaceSample plane = makePlane({10, 0.0, 1});
  const MeshTopology t(static_cast<int>(plane.points.cols()), plane.triangles);
  for (auto type : {MassType::Voronoi, MassType::MixedVoronoi}) {
    const Eigen::VectorXd m = lumpedMass(t, plane.points, type);
    for (int v = 0; v < t.numVertices(); ++v) {
      const int on_border = (std::abs(std::abs(plane.points(0, v)) - 1.0) < 1e-12) +
                            (std::abs(std::abs(plane.points(1, v)) - 1.0) < 1e-12);
      EXPECT_NEAR(m[v], 0.04 / (1 << on_border), 1e-15) << "vertex " << v;
    }
  }
}

TEST(MassMatrix, IsolatedAndDegenerateOnlyVerticesHaveZeroMass) {
  Eigen::Matrix3Xd p(3, 5);
  p << 0, 1, 0, 2, 7,  //
      0, 0, 1, 0, 7,   //
      0, 0, 0, 0, 7;
  Eigen::Matrix3Xi tris(3, 2);
  tris << 0, 0, 1, 1, 2, 3;  // (0,1,2) fine, (0,1,3) collinear
  const MeshTopology t(5, tris);
  EXPECT_EQ(makeMeshReport(t, p).zero_area_faces, 1);
  for (auto type : {MassType::Barycentric, MassType::Voronoi, MassType::MixedVoronoi}) {
    const Eigen::VectorXd m = lumpedMass(t, p, type);
    EXPECT_EQ(m[3], 0.0);
    EXPECT_EQ(m[4], 0.0);
    EXPECT_NEAR(m.sum(), 0.5, 1e-15);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
