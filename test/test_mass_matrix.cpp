// Lumped masses: each type sums to the mesh area; mixed Voronoi is non-negative where Voronoi is
// not; on a regular grid the Voronoi cell is the grid cell.
#include <gtest/gtest.h>

#include "analytic_surfaces.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/operators/mass_matrix.h"

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
  const SurfaceSample plane = makePlane({10, 0.0, 1});  // spacing 0.2, right triangles
  const MeshTopology t(static_cast<int>(plane.points.cols()), plane.triangles);
  const Eigen::VectorXd m = lumpedMass(t, plane.points, MassType::MixedVoronoi);
  for (int v = 0; v < t.numVertices(); ++v) {
    if (!t.isBoundary(v)) EXPECT_NEAR(m[v], 0.04, 1e-14);
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
