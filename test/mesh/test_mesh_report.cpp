// MeshReport: geometric defects (zero area, non-finite) and measures, on hand-made meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "analytic_surfaces.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/cloud_report.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

// Duplicates are points equal, coordinate by coordinate, to an earlier finite one: k copies of a
// point are k - 1 duplicates; -0 equals +0; a point one ulp away and a non-finite point are none.
TEST(CloudReport, DuplicatesAreExactlyEqualFinitePoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double next = std::nextafter(5.0e6, 1.0e7);
  Eigen::Matrix3Xd p(3, 9);
  p << 0.0, -0.0, 5.0e6, 5.0e6, next, 1.0, 1.0, 1.0, nan,  //
      2.0, 2.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 1.0,         //
      3.0, 3.0, 7.0, 7.0, 7.0, 3.0, 3.0, 3.0, 1.0;
  pcl::PCLPointCloud2 layout;
  layout.width = 9;
  layout.height = 1;
  const CloudReport r = makeCloudReport(layout, p);
  EXPECT_EQ(r.duplicate_points, 1 + 1 + 2);  // (+-0, 2, 3); (5e6, 1, 7); three of (1, 2, 3)
  EXPECT_EQ(r.nan_points, 1);
  // A large cloud of distinct points, then the same twice over: 0, then n duplicates.
  const int n = 200000;
  Eigen::Matrix3Xd grid(3, 2 * n);
  for (int i = 0; i < n; ++i) {
    grid.col(i) = Eigen::Vector3d(5.0e5 + 0.01 * (i % 1000), 5.0e6 + 0.01 * (i / 1000), 200.0);
    grid.col(n + i) = grid.col(i);
  }
  layout.width = n;
  EXPECT_EQ(makeCloudReport(layout, grid.leftCols(n)).duplicate_points, 0);
  layout.width = 2 * n;
  EXPECT_EQ(makeCloudReport(layout, grid).duplicate_points, n);
}

// Built a piece at a time, the report is the whole cloud's whatever the pieces: duplicates whose
// originals lie in other pieces, NaN points, the box; the second pass in another order.
TEST(CloudReport, BuiltInPiecesItIsTheWholeClouds) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const int n = 1000;
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i)
    p.col(i) = Eigen::Vector3d(5.0e5 + 0.01 * (i % 37), 5.0e6 + 0.01 * (i / 37), -3.0 * (i % 5));
  p.col(999) = p.col(3);  // 2 duplicates, their originals in the first piece
  p.col(640) = p.col(3);
  p.col(500) = p.col(501);
  p(1, 7) = nan;
  p(0, 8) = std::numeric_limits<double>::infinity();
  for (const int piece : {1, 7, 250, 999, 1000}) {
    SCOPED_TRACE(piece);
    CloudReportBuilder builder(n, 1);
    for (int first = 0; first < n; first += piece)
      builder.count(p.middleCols(first, std::min(piece, n - first)));
    for (int last = n; last > 0; last -= piece)  // backwards
      builder.compare(p.middleCols(std::max(0, last - piece), last - std::max(0, last - piece)));
    const CloudReport r = builder.report();
    EXPECT_EQ(r.points, n);
    EXPECT_EQ(r.nan_points, 2);
    EXPECT_EQ(r.duplicate_points, 3);
    EXPECT_EQ(r.bounding_box.min, Eigen::Vector3d(5.0e5, 5.0e6, -12.0));
    EXPECT_EQ(r.bounding_box.max, Eigen::Vector3d(5.0e5 + 0.01 * 36, 5.0e6 + 0.01 * 26, 0.0));
  }
}

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

// toText, line by line, on boxes whose every count is known by hand: a closed box [0,1] x [0,2] x
// [0,3] of six quads (each split into two triangles along a diagonal: 12 box edges and 6
// diagonals), and the same box without its top, with an unreferenced vertex and a triangle with a
// repeated corner.
std::map<std::string, std::string> textReportLines(const std::string& text) {
  std::map<std::string, std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t colon = line.find(':');
    EXPECT_NE(colon, std::string::npos) << line;
    if (colon == std::string::npos) continue;
    const std::size_t value = line.find_first_not_of(' ', colon + 1);
    EXPECT_EQ(lines.count(line.substr(0, colon)), 0u) << "repeated: " << line;
    lines[line.substr(0, colon)] = value == std::string::npos ? "" : line.substr(value);
  }
  return lines;
}

TEST(MeshReport, TextReportStatesEveryCountOfAClosedAndAnOpenBox) {
  Eigen::Matrix3Xd p(3, 9);
  for (int v = 0; v < 8; ++v) p.col(v) = Eigen::Vector3d(v & 1, 2 * ((v >> 1) & 1), 3 * (v >> 2));
  p.col(8) = Eigen::Vector3d(0.5, 1.0, 1.5);  // inside the box: no triangle uses it
  // Outward quads (corner index x + 2y + 4z), the top last.
  const std::vector<std::vector<int>> sides = {
      {0, 2, 3, 1}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  const std::vector<int> top = {4, 5, 7, 6};
  const double box_edges = 4 * (1.0 + 2.0 + 3.0);
  const double d12 = std::sqrt(5.0), d13 = std::sqrt(10.0), d23 = std::sqrt(13.0);

  std::vector<std::vector<int>> closed_faces = sides;
  closed_faces.push_back(top);
  const Eigen::Matrix3Xd corners = p.leftCols(8);
  const pcl::PolygonMesh closed = makeMesh(corners, closed_faces);
  const auto closed_lines = textReportLines(makeMeshReport(MeshTopology(closed), corners).toText());
  const std::map<std::string, std::string> closed_expected = {
      {"vertices", "8"},
      {"faces", "6  [4-gons: 6]"},
      {"triangles", "12"},
      {"edges", "18"},
      {"out-of-range faces", "0"},
      {"degenerate faces", "0 (zero area: 0)"},
      {"duplicate faces", "0"},
      {"boundary edges", "0 in 0 loops"},
      {"non-manifold edges", "0"},
      {"non-manifold vertices", "0"},
      {"unreferenced vertices", "0"},
      {"non-finite vertices", "0"},
      {"components", "1"},
      {"Euler characteristic", "2"},  // 8 - 18 + 12
      {"genus", "0"},
      {"orientable", "yes, consistently oriented"},
      {"bounding box", "[0 0 0] .. [1 2 3]"}};
  // The 17 facts above and the mean edge length, each once.
  EXPECT_EQ(closed_lines.size(), closed_expected.size() + 1);
  for (const auto& [label, value] : closed_expected) {
    ASSERT_EQ(closed_lines.count(label), 1u) << label;
    EXPECT_EQ(closed_lines.at(label), value) << label;
  }
  // Printed to 6 significant digits: two diagonals of each face shape.
  ASSERT_EQ(closed_lines.count("mean edge length"), 1u);
  const double closed_mean = (box_edges + 2 * (d12 + d13 + d23)) / 18;
  EXPECT_NEAR(std::stod(closed_lines.at("mean edge length")), closed_mean, 1e-5 * closed_mean);

  // Without the top: 12 box edges (the top's four are the boundary loop) and 5 diagonals;
  // V - E + T = 8 - 17 + 10 = 1 (the unreferenced vertex is not counted), a disk: no genus.
  std::vector<std::vector<int>> open_faces = sides;
  open_faces.push_back({0, 0, 1});
  const pcl::PolygonMesh open = makeMesh(p, open_faces);
  const auto open_lines = textReportLines(makeMeshReport(MeshTopology(open), p).toText());
  const std::map<std::string, std::string> open_expected = {
      {"vertices", "9"},
      {"faces", "6  [3-gons: 1]  [4-gons: 5]"},
      {"triangles", "10"},
      {"edges", "17"},
      {"degenerate faces", "1 (zero area: 0)"},
      {"boundary edges", "4 in 1 loops"},
      {"unreferenced vertices", "1"},
      {"components", "1"},
      {"Euler characteristic", "1"},
      {"genus", "n/a"},
      {"orientable", "yes, consistently oriented"},
      {"bounding box", "[0 0 0] .. [1 2 3]"}};
  EXPECT_EQ(open_lines.size(), closed_lines.size());
  for (const auto& [label, value] : open_expected) {
    ASSERT_EQ(open_lines.count(label), 1u) << label;
    EXPECT_EQ(open_lines.at(label), value) << label;
  }
  const double open_mean = (box_edges + d12 + 2 * (d13 + d23)) / 17;
  EXPECT_NEAR(std::stod(open_lines.at("mean edge length")), open_mean, 1e-5 * open_mean);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
