// MeshReport: geometric defects (zero area, non-finite) and measures, on hand-made meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "analytic_surfaces.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

TEST(MeshReport, ZeroAreaSliverIsDegenerate) {
  Eigen::Matrix3Xd p(3, 4);
  p << 0, 1, 2, 0,  //
      0, 0, 0, 1,   //
      0, 0, 0, 0;
  // Face 0 has three collinear corners; face 1 is fine.
  const pcl::PolygonMesh mesh = makeMesh(p, {{0, 1, 2}, {0, 1, 3}});
  const MeshTopology t(mesh);
  const MeshReport r = makeMeshReport(t, vertexPositions(mesh.cloud));
  EXPECT_EQ(r.zero_area_faces, 1);
  EXPECT_EQ(r.degenerate_faces, 1);
}

TEST(MeshReport, DegenerateGuardIsRelativeToScale) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0.5, 1e-9, 0);
  EXPECT_FALSE(isDegenerateTriangle(a, b, c));
  EXPECT_TRUE(isDegenerateTriangle(1e-3 * a, 1e-3 * b, 1e-3 * Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_FALSE(isDegenerateTriangle(1e-3 * a, 1e-3 * b, 1e-3 * c));
}

TEST(MeshReport, NonFiniteVertexIsCountedAndRejectedByStrictExtraction) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix3Xd p(3, 4);
  p << 0, 1, 1, nan,  //
      0, 0, 1, 1,     //
      0, 0, 0, 0;
  const pcl::PolygonMesh mesh = makeMesh(p, {{0, 1, 2}, {0, 2, 3}});
  try {
    vertexPositions(mesh.cloud);
    FAIL() << "no exception";
  } catch (const InvalidMeshException& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1 such"), std::string::npos) << e.what();
  }
  const Eigen::Matrix3Xd kept = vertexPositions(mesh.cloud, NonFinitePolicy::Keep);
  const MeshReport r = makeMeshReport(MeshTopology(mesh), kept);
  EXPECT_EQ(r.nonfinite_vertices, 1);
  EXPECT_TRUE(std::isfinite(r.mean_edge_length));
  EXPECT_EQ(r.bounding_box.max.x(), 1.0);
}

TEST(MeshReport, MeasuresOfARegularPlaneGrid) {
  const SurfaceSample plane = makePlane({10, 0.0, 1});
  const MeshTopology t(static_cast<int>(plane.points.cols()), plane.triangles);
  const MeshReport r = makeMeshReport(t, plane.points);
  // 10x10 cells of side 0.2: 220 axis edges of 0.2 and 100 diagonals of 0.2*sqrt(2).
  EXPECT_NEAR(r.mean_edge_length, (220 * 0.2 + 100 * 0.2 * std::sqrt(2.0)) / 320, 1e-12);
  EXPECT_EQ(r.edges, 320);
  EXPECT_EQ(r.boundary_edges, 40);
  EXPECT_EQ(r.boundary_loops, 1);
  EXPECT_EQ(r.euler_characteristic, 1);
  EXPECT_EQ(r.bounding_box.min, Eigen::Vector3d(-1, -1, 0));
  EXPECT_EQ(r.bounding_box.max, Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(r.genus, -1);
}

TEST(MeshReport, TriangleQualityIsTheSmallestCornerAngle) {
  // An equilateral triangle (60 degrees), a right isosceles one (45), a thin one whose smallest
  // corner is 0.5 degrees at the vertex listed last (a sliver), and a zero-area one (skipped).
  const double thin = std::tan(0.5 * M_PI / 180.0);
  Eigen::Matrix3Xd p(3, 10);
  p << 0, 1, 0.5, 2, 3, 2, 4, 5, 4, 6,                //
      0, 0, std::sqrt(0.75), 0, 0, 1, 0, 0, thin, 0,  //
      0, 0, 0, 0, 0, 0, 0, 0, 0, 0;
  const auto quality = [&](const std::vector<std::vector<int>>& faces) {
    const pcl::PolygonMesh mesh = makeMesh(p, faces);
    return triangleQuality(MeshTopology(mesh), p);
  };
  EXPECT_NEAR(quality({{0, 1, 2}}).min_angle_degrees, 60.0, 1e-12);
  EXPECT_NEAR(quality({{3, 4, 5}}).min_angle_degrees, 45.0, 1e-12);
  const TriangleQuality sliver = quality({{0, 1, 2}, {8, 6, 7}});
  EXPECT_NEAR(sliver.min_angle_degrees, 0.5, 1e-12);
  EXPECT_EQ(sliver.slivers, 1);
  const TriangleQuality flat = quality({{3, 4, 5}, {1, 3, 9}});  // 1, 3, 9 on the x axis
  EXPECT_NEAR(flat.min_angle_degrees, 45.0, 1e-12);
  EXPECT_EQ(flat.slivers, 0);
}

TEST(MeshReport, JsonHasEveryDocumentedKey) {
  const SurfaceSample sphere = makeIcosphere(1);
  const MeshReport r = makeMeshReport(
      MeshTopology(static_cast<int>(sphere.points.cols()), sphere.triangles), sphere.points);
  const std::string json = r.toJson();
  for (const char* key : {"vertices", "faces", "out_of_range_faces", "degenerate_faces",
                          "duplicate_faces", "boundary_edges", "boundary_loops",
                          "nonmanifold_edges", "nonmanifold_vertices", "unreferenced_vertices",
                          "connected_components", "euler_characteristic", "mean_edge_length"}) {
    EXPECT_NE(json.find(std::string("\"") + key + "\": "), std::string::npos) << key;
  }
  EXPECT_NE(json.find("\"genus\": 0"), std::string::npos);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
