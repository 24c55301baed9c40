// Vertex normals against exact normals, and how the weightings differ.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <pcl/exceptions.h>
#include "analytic_surfaces.h"
#include "estimator_support.h"

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/surface/mesh_normals.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

const NormalWeighting kAll[] = {NormalWeighting::Uniform, NormalWeighting::Area,
                                NormalWeighting::Angle, NormalWeighting::MeanCurvature};

double maxAngleDegrees(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < a.cols(); ++i) {
    worst = std::max(worst, std::acos(std::clamp(a.col(i).dot(b.col(i)), -1.0, 1.0)));
  }
  return worst * 180.0 / 3.14159265358979323846;
}

TEST(MeshNormals, EveryWeightingMatchesTheExactNormalOnRegularMeshes) {
  for (const SurfaceSample& s :
       {makeTorus({128, 0.0, 1}).rotateAndShiftFar(), makeIcosphere(4), makeSaddle({64, 0.0, 1})}) {
    const MeshTopology t = topologyOf(s);
    for (auto w : kAll) {
      const MeshNormals n = computeMeshNormals(t, s.points, {w});
      EXPECT_EQ(n.invalid_vertices, 0);
      EXPECT_LT(maxAngleDegrees(n.normals, s.normals), 1.0) << static_cast<int>(w);
    }
  }
}

// On irregular meshes the face-based weightings stay within a few degrees, while the
// mean-curvature direction inherits the pointwise non-convergence of the cotangent Laplacian
// (ACCURACY.md): where |H| is moderate its tangential noise tilts the normal by many degrees.
TEST(MeshNormals, JitteredMeshesFaceWeightingsStayCloseMeanCurvatureDoesNot) {
  const SurfaceSample s = makeTorus({128, 0.1, 1}).rotateAndShiftFar();
  const MeshTopology t = topologyOf(s);
  for (auto w : {NormalWeighting::Uniform, NormalWeighting::Area, NormalWeighting::Angle}) {
    EXPECT_LT(maxAngleDegrees(computeMeshNormals(t, s.points, {w}).normals, s.normals), 3.0);
  }
  const double mean_curvature_error = maxAngleDegrees(
      computeMeshNormals(t, s.points, {NormalWeighting::MeanCurvature}).normals, s.normals);
  std::printf("jittered torus, mean-curvature normals: max error %.1f deg\n", mean_curvature_error);
  EXPECT_GT(mean_curvature_error, 5.0);
  EXPECT_LT(mean_curvature_error, 45.0);
}

TEST(MeshNormals, MeanCurvatureNormalsEqualAreaNormalsOnAPlane) {
  SurfaceSample plane = makePlane({16, 0.1, 5});
  plane.rotateAndShiftFar();
  const MeshTopology t = topologyOf(plane);
  const MeshNormals mc = computeMeshNormals(t, plane.points, {NormalWeighting::MeanCurvature});
  const MeshNormals area = computeMeshNormals(t, plane.points, {NormalWeighting::Area});
  EXPECT_EQ(mc.fallback_vertices, t.numVertices());
  // The same area vectors, formed from another corner: equal up to the rounding of coordinates
  // 1e5 from the origin (measured 1.5e-6 degrees).
  EXPECT_LT(maxAngleDegrees(mc.normals, area.normals), 1e-5);
  // 1e5 from the origin the vertices are planar only to their rounding.
  EXPECT_LT(maxAngleDegrees(area.normals, plane.normals), 1e-5);
}

TEST(MeshNormals, EachWeightingChangesTheResultOnAnIrregularMesh) {
  const SurfaceSample s = makeTorus({32, 0.12, 7});
  const MeshTopology t = topologyOf(s);
  std::vector<Eigen::Matrix3Xd> results;
  for (auto w : kAll) results.push_back(computeMeshNormals(t, s.points, {w}).normals);
  for (std::size_t i = 0; i < results.size(); ++i) {
    for (std::size_t j = i + 1; j < results.size(); ++j) {
      EXPECT_GT(maxAngleDegrees(results[i], results[j]), 0.05) << i << " vs " << j;
    }
  }
}

TEST(MeshNormals, IsolatedAndSliverOnlyVerticesAreNaNAndMasked) {
  Eigen::Matrix3Xd p(3, 5);
  p << 0, 1, 0, 2, 7,  //
      0, 0, 1, 0, 7,   //
      0, 0, 0, 0, 7;
  Eigen::Matrix3Xi tris(3, 2);
  tris << 0, 0, 1, 1, 2, 3;
  const MeshTopology t(5, tris);
  for (auto w : kAll) {
    const MeshNormals n = computeMeshNormals(t, p, {w});
    EXPECT_EQ(n.invalid_vertices, 2);
    EXPECT_FALSE(n.valid[3]);
    EXPECT_FALSE(n.valid[4]);
    EXPECT_TRUE(std::isnan(n.normals(0, 4)));
    EXPECT_EQ(n.normals.col(0), Eigen::Vector3d(0, 0, 1));
  }
}

TEST(MeshNormals, FaceNormalsThatCancelGiveNaNAndACountForEveryWeightingAndForH) {
  // A square (two triangles) with the first triangle repeated in reverse, 1e5 from the origin:
  // vertex 1 lies only on the triangle and its reverse, so its face normals cancel and any
  // direction (or sign of H) would be rounding noise. Vertices 0 and 2 keep a normal.
  Eigen::Matrix3Xd x(3, 4);
  x << 0, 1, 1, 0,   //
      0, 0, 1.3, 1,  //
      0, 0.1, 0, 0.2;
  x.array() += 1e5;
  Eigen::Matrix3Xi faces(3, 3);
  faces << 0, 0, 0,  //
      1, 2, 2,       //
      2, 3, 1;
  const MeshTopology topology(4, faces);
  for (const NormalWeighting weighting : {NormalWeighting::Uniform, NormalWeighting::Area,
                                          NormalWeighting::Angle, NormalWeighting::MeanCurvature}) {
    SCOPED_TRACE(static_cast<int>(weighting));
    MeshNormalOptions options;
    options.weighting = weighting;
    const MeshNormals n = computeMeshNormals(topology, x, options);
    EXPECT_TRUE(n.normals.col(1).array().isNaN().all()) << n.normals.col(1).transpose();
    EXPECT_EQ(n.valid[1], 0);
    EXPECT_EQ(n.cancelled_vertices, 1);
    EXPECT_EQ(n.invalid_vertices, 1);
    for (const int v : {0, 2, 3}) EXPECT_NEAR(n.normals.col(v).norm(), 1.0, 1e-12);
  }
  const VertexCurvatures c = computeCurvatures(topology, x);
  EXPECT_TRUE(std::isnan(c.mean_curvature[1]) && std::isnan(c.k1[1]) && std::isnan(c.k2[1]));
  EXPECT_TRUE(std::isfinite(c.gauss_curvature[1]));  // the angle defect needs no orientation
  EXPECT_EQ(c.valid[1], 0);
  EXPECT_EQ(c.unoriented_vertices, 1);
  for (const int v : {0, 2, 3}) EXPECT_TRUE(std::isfinite(c.mean_curvature[v]));
}

TEST(MeshNormals, RealScansGiveUnitFiniteNormalsWhereValid) {
  for (const char* file : {"meshes/bun_zipper_res3.ply", "meshes/bun045_rangegrid_tri.ply"}) {
    SCOPED_TRACE(file);
    const pcl::PolygonMesh mesh = loadMesh(sharedData(file));
    const MeshTopology t(mesh);
    const Eigen::Matrix3Xd p = vertexPositions(mesh.cloud);
    for (auto w : kAll) {
      const MeshNormals n = computeMeshNormals(t, p, {w});
      // Unreferenced vertices, and on res3 vertices whose only faces are a face and its reversed
      // duplicate (their normals cancel), have no normal.
      EXPECT_GE(n.invalid_vertices, t.counts().unreferenced_vertices);
      EXPECT_LE(n.invalid_vertices, t.counts().unreferenced_vertices + 10);
      for (Eigen::Index i = 0; i < p.cols(); ++i) {
        if (n.valid[i]) ASSERT_NEAR(n.normals.col(i).norm(), 1.0, 1e-12);
      }
    }
  }
}

// Area and uniform normals sum each vertex's triangles in ascending order: to the bit what a
// gather over incidentTriangles() with the textbook face normals gives, on a scan with duplicate
// and degenerate faces.
TEST(MeshNormals, FaceWeightingsSumEachVertexsTrianglesInOrder) {
  const pcl::PolygonMesh mesh = loadMesh(sharedData("meshes/bun_zipper_res3.ply"));
  const MeshTopology topology(mesh);
  const Eigen::Matrix3Xd p = vertexPositions(mesh.cloud);
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  for (const NormalWeighting w : {NormalWeighting::Area, NormalWeighting::Uniform}) {
    const MeshNormals normals = computeMeshNormals(topology, p, {w});
    for (int v = 0; v < topology.numVertices(); ++v) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const int t : topology.incidentTriangles(v)) {
        const Eigen::Vector3d a = p.col(triangles(0, t)), b = p.col(triangles(1, t)),
                              c = p.col(triangles(2, t));
        if (isDegenerateTriangle(a, b, c)) continue;
        const Eigen::Vector3d area_vector = 0.5 * (b - a).cross(c - a);
        sum += w == NormalWeighting::Area ? area_vector
                                          : Eigen::Vector3d(area_vector / area_vector.norm());
      }
      if (!normals.valid[v]) continue;
      const Eigen::Vector3d expected = sum / sum.norm();
      ASSERT_EQ(normals.normals.col(v), expected) << "vertex " << v;
    }
  }
}

TEST(MeshNormals, EpsilonOnlyForMeanCurvature) {
  const SurfaceSample s = makeIcosphere(1);
  EXPECT_THROW(computeMeshNormals(topologyOf(s), s.points, {NormalWeighting::Area, 0.1}),
               pcl::BadArgumentException);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
