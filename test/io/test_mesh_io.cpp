// Every loader on every file of the shared data, round trips, and broken files.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <pcl/conversions.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>

#include "data_catalogue.h"
#include "io/mesh_formats.h"  // internal: the ascii OFF parser's own cloud
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/atomic_file.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

TEST(MeshIO, EverySharedFileLoadsWithItsCatalogCounts) {
  for (const SharedMesh& e : sharedMeshes()) {
    SCOPED_TRACE(e.path);
    const pcl::PolygonMesh mesh = loadMesh(sharedData(e.path));
    EXPECT_EQ(static_cast<int>(mesh.cloud.width * mesh.cloud.height), e.vertices);
    EXPECT_EQ(static_cast<int>(mesh.polygons.size()), e.faces);
  }
  for (const SharedCloud& e : sharedClouds()) {
    SCOPED_TRACE(e.path);
    const pcl::PolygonMesh cloud = loadMesh(sharedData(e.path));
    EXPECT_EQ(static_cast<int>(cloud.cloud.width * cloud.cloud.height), e.points);
    EXPECT_TRUE(cloud.polygons.empty());
  }
}

/** The faces of a file read as rows, as polygons (each row one polygon). */
std::vector<pcl::Vertices> polygonsOfRows(const FaceRows& rows) {
  std::vector<pcl::Vertices> polygons(rows.rows());
  for (std::size_t f = 0; f < rows.rows(); ++f)
    polygons[f].vertices.assign(rows.indices.begin() + f * rows.corners,
                                rows.indices.begin() + (f + 1) * rows.corners);
  return polygons;
}

void expectSameTopology(const MeshTopology& a, const MeshTopology& b) {
  EXPECT_EQ(a.triangles(), b.triangles());
  EXPECT_EQ(a.counts().input_polygons, b.counts().input_polygons);
  EXPECT_EQ(a.counts().duplicate_polygons, b.counts().duplicate_polygons);
  EXPECT_EQ(a.counts().repeated_index_polygons, b.counts().repeated_index_polygons);
  EXPECT_EQ(a.counts().triangulated_polygons, b.counts().triangulated_polygons);
  EXPECT_EQ(a.counts().nonmanifold_edges, b.counts().nonmanifold_edges);
  EXPECT_EQ(a.counts().polygons_by_valence, b.counts().polygons_by_valence);
  EXPECT_EQ(a.numEdges(), b.numEdges());
}

// The tools read faces as rows (no heap vector per face): the same faces, in the same order, and
// the same topology as PCL's polygons give, for every shared mesh.
TEST(MeshIO, FacesAsRowsAreThePolygonsOfEverySharedMesh) {
  for (const SharedMesh& e : sharedMeshes()) {
    SCOPED_TRACE(e.path);
    const MeshFile polygons = readMeshFile(sharedData(e.path));
    const MeshFile rows =
        readMeshFile(sharedData(e.path), EmptyFilePolicy::Refuse, FaceStorage::Rows);
    ASSERT_TRUE(rows.faces) << "every shared mesh has faces of one size";
    EXPECT_TRUE(rows.mesh.polygons.empty());
    EXPECT_EQ(static_cast<int>(rows.faces->rows()), e.faces);
    const std::vector<pcl::Vertices> read_back = polygonsOfRows(*rows.faces);
    ASSERT_EQ(read_back.size(), polygons.mesh.polygons.size());
    for (std::size_t f = 0; f < read_back.size(); ++f)
      ASSERT_EQ(read_back[f].vertices, polygons.mesh.polygons[f].vertices) << "face " << f;
    EXPECT_EQ(rows.positions, polygons.positions);
    const int n = static_cast<int>(polygons.positions.cols());
    expectSameTopology(MeshTopology(n, PolygonList(rows.faces->indices.data(), rows.faces->rows(),
                                                   rows.faces->corners)),
                       MeshTopology(polygons.mesh));
  }
}

TEST(MeshIO, RangeGridBecomesAnOrganizedCloudWithHoles) {
  const pcl::PolygonMesh scan = loadMesh(sharedData("range/bun000.ply"));
  EXPECT_EQ(scan.cloud.width, 512u);
  EXPECT_EQ(scan.cloud.height, 400u);
  const Eigen::Matrix3Xd p = vertexPositions(scan.cloud, NonFinitePolicy::Keep);
  EXPECT_EQ(p.cols() - findNonFiniteVertices(p).count, 40256);  // the file's vertex count
}

TEST(MeshIO, TristripsGiveTheSameSurfaceAsFaces) {
  // igea.ply stores its faces as one strip: the result must be a closed, consistently
  // oriented surface (a wrong strip winding would break the orientation).
  const pcl::PolygonMesh igea = loadMesh(sharedData("meshes/igea.ply"));
  const MeshTopology t(igea);
  EXPECT_EQ(t.counts().boundary_edges, 0);
  EXPECT_TRUE(t.counts().consistently_oriented);
  EXPECT_EQ(t.eulerCharacteristic(), 2);
}

TEST(MeshIO, CrlfOffAndExtraVertexFieldsAreRead) {
  const pcl::PolygonMesh rocker = loadMesh(sharedData("meshes/rocker-arm.off"));
  EXPECT_EQ(MeshTopology(rocker).genus(), 1);
  const pcl::PolygonMesh zipper = loadMesh(sharedData("meshes/bun_zipper.ply"));
  std::vector<std::string> names;
  for (const auto& f : zipper.cloud.fields) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"x", "y", "z", "confidence", "intensity"}));
}

class MeshIOFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

TEST_F(MeshIOFiles, FacesOfMixedSizesStayPolygonsAndQuadsBecomeRowsOfFour) {
  const std::string vertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n";
  // A triangle then a quad: the ascii OFF reader starts with rows and reads the faces again.
  writeText(path("mixed.off"), "OFF\n5 2 0\n" + vertices + "3 1 4 2\n4 0 1 2 3\n");
  const MeshFile mixed =
      readMeshFile(path("mixed.off"), EmptyFilePolicy::Refuse, FaceStorage::Rows);
  EXPECT_FALSE(mixed.faces);
  ASSERT_EQ(mixed.mesh.polygons.size(), 2u);
  EXPECT_EQ(mixed.mesh.polygons[0].vertices, (pcl::Indices{1, 4, 2}));
  EXPECT_EQ(mixed.mesh.polygons[1].vertices, (pcl::Indices{0, 1, 2, 3}));
  writeText(path("quads.off"), "OFF\n5 2 0\n" + vertices + "4 0 1 2 3\n4 1 4 2 3\n");
  const MeshFile quads =
      readMeshFile(path("quads.off"), EmptyFilePolicy::Refuse, FaceStorage::Rows);
  ASSERT_TRUE(quads.faces);
  EXPECT_EQ(quads.faces->corners, 4u);
  EXPECT_EQ(quads.faces->indices, (std::vector<std::int32_t>{0, 1, 2, 3, 1, 4, 2, 3}));
  expectSameTopology(MeshTopology(5, PolygonList(quads.faces->indices.data(), 2, 4)),
                     MeshTopology(readMeshFile(path("quads.off")).mesh));
  // The first bad face by line order is the one named, rows or not (here after a quad).
  writeText(path("bad.off"), "OFF\n5 3 0\n" + vertices + "3 0 1 2\n4 0 1 2 3\n3 0 x 2\n");
  std::string as_polygons, as_rows;
  try {
    readMeshFile(path("bad.off"));
  } catch (const FileFormatException& e) {
    as_polygons = e.what();
  }
  try {
    readMeshFile(path("bad.off"), EmptyFilePolicy::Refuse, FaceStorage::Rows);
  } catch (const FileFormatException& e) {
    as_rows = e.what();
  }
  EXPECT_FALSE(as_polygons.empty());
  EXPECT_EQ(as_rows, as_polygons);
}

// Adding, replacing and removing fields gives the same rows whether the cloud's block has room
// for them (readMeshFile's spare bytes: rewritten in place, back to front when rows grow) or not
// (a new block); in place the block stays where it is.
TEST(VertexFields, FieldsChangeInPlaceWhenTheBlockHasRoomAndAlikeWhenNot) {
  const int n = 1000;
  Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Random(3, n) * 1000.0;
  p.col(7) << 5.0e5 + 0.125, 5.0e6 + 0.25, 200.0;
  const pcl::PolygonMesh base = makeMesh(p.cast<float>().cast<double>(), {});
  Eigen::MatrixXd values = Eigen::MatrixXd::Random(2, n);
  pcl::PointCloud<pcl::Normal> normals;
  for (int i = 0; i < n; ++i) {
    pcl::Normal m;
    m.normal_x = 0.5f * i, m.normal_y = -1.0f * i, m.normal_z = 0.25f, m.curvature = 1e-3f * i;
    normals.push_back(m);
  }
  const Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>> triple(
      reinterpret_cast<const float*>(normals.points.data()), 3, n, Eigen::OuterStride<>(8));
  std::vector<std::uint8_t> rows[2];
  for (const bool room : {false, true}) {
    pcl::PCLPointCloud2 cloud = base.cloud;
    if (room) cloud.data.reserve(cloud.data.size() + 64 * n);
    const std::uint8_t* block = cloud.data.data();
    setVertexFields(cloud, {"a", "b"}, values, FieldPrecision::Double);
    setVertexFields(cloud, {"nx", "ny", "nz"}, triple, FieldPrecision::Float);
    setVertexCoordinates(cloud, p, FieldPrecision::Double);  // double x y z go first
    EXPECT_TRUE(removeVertexField(cloud, "a"));
    setVertexField(cloud, "b", values.row(0).transpose(), FieldPrecision::Float);  // replaced
    EXPECT_EQ(cloud.data.data() == block, room);
    EXPECT_TRUE(vertexPositions(cloud) == p);
    EXPECT_FALSE(hasVertexField(cloud, "a"));
    EXPECT_TRUE(vertexScalarField(cloud, "b") ==
                values.row(0).transpose().cast<float>().cast<double>());
    const char* names[] = {"nx", "ny", "nz"};
    for (int d = 0; d < 3; ++d) {
      EXPECT_TRUE(vertexScalarField(cloud, names[d]) == triple.row(d).transpose().cast<double>())
          << names[d];
    }
    rows[room] = cloud.data;
  }
  EXPECT_TRUE(rows[0] == rows[1]);
}

// Fields laid out first and written a slice at a time are the fields setVertexFields writes at
// once, float and double, and NaN where no slice was written; a missing field or a slice past the
// last point is refused.
TEST(VertexFields, FieldsWrittenASliceAtATimeAreTheFieldsWrittenAtOnce) {
  const int n = 1000;
  const pcl::PolygonMesh base = makeMesh(Eigen::Matrix3Xd::Random(3, n), {});
  const Eigen::MatrixXf values = Eigen::MatrixXf::Random(2, n);
  const auto slice = [&](int first, int count) {
    return Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>(
        values.data() + 2 * first, 2, count, Eigen::OuterStride<>(2));
  };
  for (const FieldPrecision precision : {FieldPrecision::Float, FieldPrecision::Double}) {
    pcl::PCLPointCloud2 at_once = base.cloud, sliced = base.cloud;
    setVertexFields(at_once, {"a", "b"}, slice(0, n), precision);
    addVertexFields(sliced, {"a", "b"}, precision);
    for (int first = 0; first < n - 100; first += 300)
      setVertexFieldSlice(sliced, {"a", "b"}, first, slice(first, std::min(300, n - 100 - first)));
    EXPECT_TRUE(std::isnan(vertexScalarField(sliced, "b")[n - 1]));
    setVertexFieldSlice(sliced, {"a", "b"}, n - 100, slice(n - 100, 100));
    EXPECT_EQ(sliced.fields.size(), at_once.fields.size());
    EXPECT_TRUE(sliced.data == at_once.data);
    EXPECT_THROW(setVertexFieldSlice(sliced, {"a", "b"}, n - 99, slice(0, 100)),
                 pcl::BadArgumentException);
    EXPECT_THROW(setVertexFieldSlice(sliced, {"a", "c"}, 0, slice(0, 100)),
                 pcl::BadArgumentException);
  }
}

// A compressed PCD whose one value is larger than the writer's block (a field of COUNT 300,000
// floats: 1.2 MB a point) is written across blocks and read back byte for byte.
TEST_F(MeshIOFiles, APcdValueLargerThanACompressionBlockIsWrittenWhole) {
  pcl::PolygonMesh mesh;
  mesh.cloud.width = 3;
  mesh.cloud.height = 1;
  const std::uint32_t count = 300000;
  std::uint32_t offset = 0;
  for (const char* name : {"x", "y", "z", "h"}) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = pcl::PCLPointField::FLOAT32;
    f.count = name[0] == 'h' ? count : 1;
    offset += 4 * f.count;
    mesh.cloud.fields.push_back(f);
  }
  mesh.cloud.point_step = offset;
  mesh.cloud.row_step = 3 * offset;
  mesh.cloud.data.resize(3 * std::size_t{offset});
  for (std::size_t i = 0; i < mesh.cloud.data.size() / 4; ++i) {
    const float v = static_cast<float>(i % 977) * 0.5f;
    std::memcpy(mesh.cloud.data.data() + 4 * i, &v, 4);
  }
  saveMesh(path("wide.pcd"), mesh);
  const MeshFile back = readMeshFile(path("wide.pcd"));
  ASSERT_EQ(back.mesh.cloud.point_step, mesh.cloud.point_step);
  EXPECT_TRUE(back.mesh.cloud.data == mesh.cloud.data);
}

TEST_F(MeshIOFiles, PlyRoundTripKeepsDoublesFieldsAndFaces) {
  Eigen::Matrix3Xd p(3, 4);
  p << 100000.123456789012, 1, 1, 0,  //
      0, 0, 1, 1,                     //
      0, 0, 0, 1e-300;
  pcl::PolygonMesh mesh = makeMesh(Eigen::Matrix3Xd::Zero(3, 4), {{0, 1, 2, 3}});
  // Replace float x/y/z by doubles and add a scalar field and colours.
  for (const char* axis : {"x", "y", "z"}) removeVertexField(mesh.cloud, axis);
  setVertexField(mesh.cloud, "x", p.row(0).transpose(), FieldPrecision::Double);
  setVertexField(mesh.cloud, "y", p.row(1).transpose(), FieldPrecision::Double);
  setVertexField(mesh.cloud, "z", p.row(2).transpose(), FieldPrecision::Double);
  setVertexField(mesh.cloud, "mean_curvature", Eigen::Vector4d(1, 2, 3, 4));
  Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> rgb(3, 4);
  rgb.setConstant(7);
  setVertexColors(mesh.cloud, rgb);
  for (PlyEncoding encoding : {PlyEncoding::Binary, PlyEncoding::Ascii}) {
    saveMesh(path("out.ply"), mesh, {encoding});
    const MeshFile file = readMeshFile(path("out.ply"));
    EXPECT_EQ(file.positions, p);  // bit-exact, both encodings
    EXPECT_EQ(file.coordinate_precision, FieldPrecision::Double);
    const pcl::PolygonMesh& back = file.mesh;
    EXPECT_EQ(vertexPositions(back.cloud), p.cast<float>().cast<double>());  // PCL gets floats
    ASSERT_EQ(back.polygons.size(), 1u);
    EXPECT_EQ(back.polygons[0].vertices.size(), 4u);
    std::vector<std::string> names;
    for (const auto& f : back.cloud.fields) names.push_back(f.name);
    EXPECT_EQ(names,
              (std::vector<std::string>{"x", "y", "z", "mean_curvature", "red", "green", "blue"}));
  }
}

// What PCL code does with a loaded mesh: pcl::fromPCLPointCloud2 into its own point type. It
// matches fields by name and type, so anything but FLOAT32 x, y, z would give zeros.
void expectPCLReadsTheCoordinates(const std::string& path) {
  SCOPED_TRACE(path);
  const MeshFile file = readMeshFile(path);
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(file.mesh.cloud, points);
  ASSERT_EQ(static_cast<Eigen::Index>(points.size()), file.positions.cols());
  std::int64_t finite = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f expected = file.positions.col(static_cast<Eigen::Index>(i)).cast<float>();
    if (!expected.allFinite()) {
      EXPECT_FALSE(std::isfinite(points[i].x)) << "vertex " << i;
      continue;
    }
    ++finite;
    ASSERT_EQ(points[i].getVector3fMap(), expected) << "vertex " << i;
  }
  EXPECT_GT(finite, 0);
}

TEST(MeshIO, PCLReadsFloatCoordinatesFromEveryLoadedSharedFile) {
  for (const SharedMesh& e : sharedMeshes()) expectPCLReadsTheCoordinates(sharedData(e.path));
  for (const SharedCloud& e : sharedClouds()) expectPCLReadsTheCoordinates(sharedData(e.path));
  expectPCLReadsTheCoordinates(sharedData("range/bun000.ply"));
}

TEST_F(MeshIOFiles, PCLReadsFloatCoordinatesFromEveryFormatAndPrecision) {
  const std::string triangle = "0.1 0.2 0.3\n100000.123456789 1 0\n0 1e-30 1\n";
  writeText(path("t.off"), "OFF\n3 1 0\n" + triangle + "3 0 1 2\n");
  writeText(path("t.obj"), "v 0.1 0.2 0.3\nv 100000.123456789 1 0\nv 0 1e-30 1\nf 1 2 3\n");
  writeText(path("t.vtk"),
            "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 double\n" + triangle +
                "POLYGONS 1 4\n3 0 1 2\n");
  writeText(path("t.stl"),
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0.1 0.2 0.3\n"
            "vertex 100000.123456789 1 0\nvertex 0 1e-30 1\nendloop\nendfacet\nendsolid t\n");
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\n";
  writeText(path("double.ply"), header +
                                    "property double x\nproperty double y\nproperty double z\n"
                                    "element face 1\nproperty list uchar int vertex_indices\n"
                                    "end_header\n" +
                                    triangle + "3 0 1 2\n");
  writeText(path("int.ply"), header +
                                 "property int x\nproperty short y\nproperty uchar z\n"
                                 "end_header\n1 2 3\n4 5 6\n7 8 9\n");
  writeText(path("double.pcd"),
            "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\n"
            "HEIGHT 1\nPOINTS 3\nDATA ascii\n" +
                triangle);
  for (const char* name :
       {"t.off", "t.obj", "t.vtk", "t.stl", "double.ply", "int.ply", "double.pcd"})
    expectPCLReadsTheCoordinates(path(name));
  // The exact coordinates stay beside the mesh, and a declared double is remembered.
  const MeshFile off = readMeshFile(path("t.off"));
  EXPECT_EQ(off.positions(0, 1), 100000.123456789);
  EXPECT_EQ(off.coordinate_precision, FieldPrecision::Float);  // untyped text
  for (const char* name : {"t.vtk", "double.ply", "double.pcd"}) {
    EXPECT_EQ(readMeshFile(path(name)).positions(0, 1), 100000.123456789) << name;
    EXPECT_EQ(readMeshFile(path(name)).coordinate_precision, FieldPrecision::Double) << name;
  }
}

// The ascii OFF parser holds the coordinates exactly in its cloud, parsed straight into it: as
// float when every one is a float's value (narrowed in place), else as double; readMeshFile then
// keeps them in positions and gives PCL floats.
TEST_F(MeshIOFiles, TextCoordinatesAreFloatWhenExactlyFloatElseDouble) {
  const auto types = [](const pcl::PCLPointCloud2& cloud) {
    std::string names;
    for (const pcl::PCLPointField& f : cloud.fields)
      names += f.name + std::to_string(f.datatype) + "@" + std::to_string(f.offset) + " ";
    return names + "step " + std::to_string(cloud.point_step);
  };
  const std::string floats = "OFF\n3 1 0\n0.5 -2 1e3\n0.25 1 0\n0 0.125 nan\n3 0 1 2\n";
  const pcl::PolygonMesh exact = detail::parseOFF(floats);
  EXPECT_EQ(types(exact.cloud), "x7@0 y7@4 z7@8 step 12");  // PCLPointField::FLOAT32 = 7
  EXPECT_EQ(exact.cloud.data.size(), 36u);
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(exact.cloud, points);
  EXPECT_EQ(points[0].z, 1000.0f);
  EXPECT_EQ(points[1].x, 0.25f);
  EXPECT_EQ(points[2].y, 0.125f);
  EXPECT_TRUE(std::isnan(points[2].z));
  EXPECT_FALSE(exact.cloud.is_dense);

  const std::string text = "OFF\n3 1 0\n0.1 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const pcl::PolygonMesh wide = detail::parseOFF(text);
  EXPECT_EQ(types(wide.cloud), "x8@0 y8@8 z8@16 step 24");  // FLOAT64 = 8
  double x = 0.0;
  std::memcpy(&x, wide.cloud.data.data(), 8);
  EXPECT_EQ(x, 0.1);
  EXPECT_TRUE(wide.cloud.is_dense);
  writeText(path("double.off"), text);
  const MeshFile file = readMeshFile(path("double.off"));
  EXPECT_EQ(types(file.mesh.cloud), "x7@0 y7@4 z7@8 step 12");
  EXPECT_EQ(file.positions(0, 0), 0.1);
  pcl::fromPCLPointCloud2(file.mesh.cloud, points);
  EXPECT_EQ(points[0].x, 0.1f);
}

TEST_F(MeshIOFiles, CoordinatesBeyondFloatAreRefused) {
  writeText(path("huge.off"), "OFF\n3 1 0\n0 0 0\n1e300 0 0\n0 1 0\n3 0 1 2\n");
  try {
    loadMesh(path("huge.off"));
    ADD_FAILURE() << "loaded";
  } catch (const FileFormatException& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 1: coordinate 1e+300 is beyond float"),
              std::string::npos)
        << e.what();
  }
}

// A field with COUNT 3 before x y z: each point is 6 floats, x at byte 12 (the specification:
// a field takes SIZE x COUNT bytes). Ascii and binary, both against the values written.
TEST_F(MeshIOFiles, PcdFieldsWithACountAboveOneTakeThatManyValues) {
  const float rows[2][6] = {{9, 8, 7, 1.5f, 2.5f, 3.5f}, {6, 5, 4, -1, -2, -3}};
  const std::string header =
      "VERSION .7\nFIELDS tag x y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 3 1 1 1\nWIDTH 2\n"
      "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n";
  {
    std::ofstream ascii(path("ascii.pcd"));
    ascii << header << "DATA ascii\n";
    for (const auto& row : rows) {
      for (int k = 0; k < 6; ++k) ascii << row[k] << (k < 5 ? " " : "\n");
    }
    std::ofstream binary(path("binary.pcd"), std::ios::binary);
    binary << header << "DATA binary\n";
    binary.write(reinterpret_cast<const char*>(rows), sizeof rows);
  }
  for (const char* name : {"ascii.pcd", "binary.pcd"}) {
    const Eigen::Matrix3Xd positions = vertexPositions(loadMesh(path(name)).cloud);
    ASSERT_EQ(positions.cols(), 2) << name;
    for (int i = 0; i < 2; ++i) {
      for (int d = 0; d < 3; ++d) EXPECT_EQ(positions(d, i), rows[i][3 + d]) << name;
    }
  }
}

TEST_F(MeshIOFiles, PcdRoundTrip) {
  const pcl::PolygonMesh cloud = loadMesh(sharedData("clouds/milk.pcd"));
  saveMesh(path("milk.pcd"), cloud);
  const pcl::PolygonMesh back = loadMesh(path("milk.pcd"));
  EXPECT_EQ(vertexPositions(back.cloud), vertexPositions(cloud.cloud));
}

TEST_F(MeshIOFiles, HandWrittenObjOffStlVtk) {
  writeText(path("quad.obj"),
            "# comment\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
            "f 1/1/1 2/1/1 3/1/1\nf -4//1 -2//1 -1//1\n");
  writeText(path("quad.off"),
            "OFF\r\n# c\r\n4 2 0\r\n0 0 0\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n"
            "3 0 1 2 255 0 0\r\n3 0 2 3\r\n");
  writeText(path("quad.stl"),
            "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n"
            "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\n"
            "vertex 0 1 0\nendloop\nendfacet\nendsolid q\n");
  writeText(path("quad.vtk"),
            "# vtk DataFile Version 3.0\nquad\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
            "0 0 0 1 0 0 1 1 0 0 1 0\nPOLYGONS 2 8\n3 0 1 2\n3 0 2 3\nPOINT_DATA 4\n");
  writeText(path("quad51.vtk"),
            "# vtk DataFile Version 5.1\nquad\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
            "0 0 0 1 0 0 1 1 0 0 1 0\nPOLYGONS 3 6\nOFFSETS vtktypeint64\n0 3 6\n"
            "CONNECTIVITY vtktypeint64\n0 1 2 0 2 3\n");
  for (const char* name : {"quad.obj", "quad.off", "quad.stl", "quad.vtk", "quad51.vtk"}) {
    SCOPED_TRACE(name);
    const pcl::PolygonMesh mesh = loadMesh(path(name));
    ASSERT_EQ(mesh.cloud.width, 4u);
    ASSERT_EQ(mesh.polygons.size(), 2u);
    const MeshTopology t(mesh);
    EXPECT_EQ(t.numEdges(), 5);
    EXPECT_TRUE(t.counts().consistently_oriented);
    EXPECT_EQ(vertexPositions(mesh.cloud).col(2), Eigen::Vector3d(1, 1, 0));
  }
}

TEST_F(MeshIOFiles, BinaryStlMergesSharedCorners) {
  {
    std::ofstream stl(path("tri.stl"), std::ios::binary);
    stl << std::string(80, ' ');
    const std::uint32_t n = 2;
    stl.write(reinterpret_cast<const char*>(&n), 4);
    const float facets[2][12] = {{0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 1, 0},
                                 {0, 0, 1, 0, 0, 0, 1, 1, 0, 0, 1, 0}};
    for (const auto& f : facets) {
      stl.write(reinterpret_cast<const char*>(f), sizeof(f));
      stl.write("\0\0", 2);
    }
  }
  const pcl::PolygonMesh stl = loadMesh(path("tri.stl"));
  EXPECT_EQ(stl.cloud.width, 4u);  // shared corners merged
  EXPECT_EQ(stl.polygons.size(), 2u);
}

TEST_F(MeshIOFiles, BinaryOffIsBigEndian) {
  std::string data = "OFF BINARY\n";
  auto put = [&](auto value) {
    std::string bytes(sizeof(value), '\0');
    std::memcpy(bytes.data(), &value, sizeof(value));
    data.append(bytes.rbegin(), bytes.rend());
  };
  for (std::int32_t count : {3, 1, 0}) put(count);
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 2.f, 0.f}) put(v);
  for (std::int32_t v : {3, 0, 1, 2, 0}) put(v);  // corners, then no colour values
  writeText(path("tri.off"), data);
  const pcl::PolygonMesh mesh = loadMesh(path("tri.off"));
  ASSERT_EQ(mesh.polygons.size(), 1u);
  EXPECT_EQ(vertexPositions(mesh.cloud).col(2), Eigen::Vector3d(0, 2, 0));
  writeText(path("tri.off"), data.substr(0, data.size() - 6));
  EXPECT_THROW(loadMesh(path("tri.off")), FileFormatException);
}

enum class Endian { Big, Little };
enum class FaceEnd { ColourCount, Nothing };  // Geomview's spec, pmp-library's write_off

struct BinaryFace {
  std::vector<std::int32_t> corners;
  std::vector<float> colour;  // Geomview's layout only
};

// A binary OFF composed from the two layouts' definitions (not by a writer of ours): the header
// line, int32 counts, float32 vertices, each face as `n i0 .. i(n-1)` followed, in Geomview's
// layout, by a colour count and that many float32 values.
std::string binaryOff(const std::vector<float>& xyz, const std::vector<BinaryFace>& faces,
                      Endian endian, FaceEnd face_end) {
  std::string data = "OFF BINARY\n";
  const auto put = [&](auto value) {
    std::string bytes(sizeof(value), '\0');
    std::memcpy(bytes.data(), &value, sizeof(value));
    if (endian == Endian::Big) std::reverse(bytes.begin(), bytes.end());
    data += bytes;
  };
  for (const std::int32_t count :
       {static_cast<std::int32_t>(xyz.size() / 3), static_cast<std::int32_t>(faces.size()), 0}) {
    put(count);
  }
  for (const float v : xyz) put(v);
  for (const BinaryFace& face : faces) {
    put(static_cast<std::int32_t>(face.corners.size()));
    for (const std::int32_t corner : face.corners) put(corner);
    if (face_end == FaceEnd::Nothing) continue;
    put(static_cast<std::int32_t>(face.colour.size()));
    for (const float c : face.colour) put(c);
  }
  return data;
}

// A square pyramid far from the origin, so that a wrong byte order or offset cannot pass.
const std::vector<float> kPyramid = {100000.5f, -2.25f, 3e-5f,  //
                                     100001.5f, -2.25f, 3e-5f,  //
                                     100001.5f, -1.25f, 3e-5f,  //
                                     100000.5f, -1.25f, 3e-5f,  //
                                     100001.f,  -1.75f, 0.8125f};
const std::vector<BinaryFace> kPyramidFaces = {{{0, 3, 2, 1}, {}},
                                               {{0, 1, 4}, {0.5f}},
                                               {{1, 2, 4}, {1.f, 0.f, 0.f}},
                                               {{2, 3, 4}, {0.f, 1.f, 0.f, 0.5f}},
                                               {{3, 0, 4}, {}}};

void expectPyramid(const pcl::PolygonMesh& mesh) {
  const Eigen::Matrix3Xd p = vertexPositions(mesh.cloud);
  ASSERT_EQ(p.cols(), 5);
  for (int i = 0; i < 15; ++i) EXPECT_EQ(p(i % 3, i / 3), static_cast<double>(kPyramid[i])) << i;
  ASSERT_EQ(mesh.polygons.size(), kPyramidFaces.size());
  for (std::size_t f = 0; f < kPyramidFaces.size(); ++f) {
    const std::vector<std::int32_t>& expected = kPyramidFaces[f].corners;
    EXPECT_EQ(mesh.polygons[f].vertices,
              std::vector<pcl::index_t>(expected.begin(), expected.end()))
        << "face " << f;
  }
}

// pmp-library's write_off (binary) ends a face after its corners, in host (little-endian) order.
TEST_F(MeshIOFiles, BinaryOffInPmpLibraryLayoutIsRead) {
  for (const Endian endian : {Endian::Little, Endian::Big}) {
    SCOPED_TRACE(endian == Endian::Big ? "big-endian" : "little-endian");
    writeText(path("pmp.off"), binaryOff(kPyramid, kPyramidFaces, endian, FaceEnd::Nothing));
    expectPyramid(loadMesh(path("pmp.off")));
  }
}

TEST_F(MeshIOFiles, BinaryOffInGeomviewLayoutIsRead) {
  for (const Endian endian : {Endian::Big, Endian::Little}) {
    SCOPED_TRACE(endian == Endian::Big ? "big-endian" : "little-endian");
    const std::string data = binaryOff(kPyramid, kPyramidFaces, endian, FaceEnd::ColourCount);
    writeText(path("geomview.off"), data);
    expectPyramid(loadMesh(path("geomview.off")));
    writeText(path("cgal.off"), data + "\n");  // CGAL's writer ends with a newline
    expectPyramid(loadMesh(path("cgal.off")));
  }
}

// The message of the FileFormatException that loading `data` throws ("" if it loads).
std::string binaryOffError(const std::string& file, const std::string& data) {
  writeText(file, data);
  try {
    loadMesh(file);
  } catch (const FileFormatException& e) {
    return errorDescription(e);
  }
  return "";
}

TEST_F(MeshIOFiles, BinaryOffFittingNoLayoutIsRefusedWithByteOffsets) {
  // Header 11 bytes, counts 12, vertices 60: the faces start at byte 83; the pmp layout's last
  // face (3 corners) at 151, 2 bytes short of the 167 it needs.
  const std::string pmp = binaryOff(kPyramid, kPyramidFaces, Endian::Little, FaceEnd::Nothing);
  ASSERT_EQ(pmp.size(), 167u);
  const std::string truncated = binaryOffError(path("truncated.off"), pmp.substr(0, 165));
  for (const char* expected : {"fits neither Geomview's", "nor pmp-library's",
                               "pmp-library little-endian at byte offset 151: face 4 of 5 has 3",
                               "Geomview little-endian at byte offset", "big-endian: the counts"}) {
    EXPECT_NE(truncated.find(expected), std::string::npos) << expected << " in " << truncated;
  }
  EXPECT_EQ(truncated.find("line"), std::string::npos) << truncated;

  // A colour count beyond the spec's 0..4, in Geomview's byte order: neither layout fits.
  std::vector<BinaryFace> faces = kPyramidFaces;
  faces[1].colour.assign(7, 0.f);
  const std::string colours = binaryOffError(
      path("colours.off"), binaryOff(kPyramid, faces, Endian::Big, FaceEnd::ColourCount));
  EXPECT_NE(colours.find("Geomview big-endian at byte offset 123: face 1 of 5 has colour count 7"),
            std::string::npos)
      << colours;
  EXPECT_NE(colours.find("pmp-library big-endian at byte offset"), std::string::npos) << colours;
  EXPECT_EQ(colours.find("line"), std::string::npos) << colours;

  // Bytes after the last face (not whitespace).
  const std::string trailing = binaryOffError(path("trailing.off"), pmp + "abcd");
  EXPECT_NE(trailing.find("pmp-library little-endian at byte offset 167: 4 bytes left"),
            std::string::npos)
      << trailing;

  // Counts that fit the file in neither byte order.
  EXPECT_NE(binaryOffError(path("counts.off"), pmp.substr(0, 40)).find("byte offset 11:"),
            std::string::npos);
  // Per-vertex normals would be read as coordinates.
  EXPECT_NE(binaryOffError(path("noff.off"), "N" + pmp).find("binary NOFF is not supported"),
            std::string::npos);
}

TEST_F(MeshIOFiles, SavedFilesHaveOrdinaryPermissions) {
  saveMesh(path("p.ply"), makeMesh(Eigen::Matrix3Xd::Zero(3, 3), {{0, 1, 2}}));
  const auto perms = std::filesystem::status(path("p.ply")).permissions();
  EXPECT_NE(perms & std::filesystem::perms::group_read, std::filesystem::perms::none);
}

TEST_F(MeshIOFiles, TruncatedFilesFailWithAMessage) {
  for (const char* file :
       {"meshes/bun_zipper_res4.ply", "meshes/horse.ply", "meshes/igea.ply", "meshes/cow.off",
        "meshes/tum_rabbit.vtk", "clouds/milk.pcd", "clouds/office1.pcd"}) {
    SCOPED_TRACE(file);
    const std::string data = [&] {
      std::ifstream in(sharedData(file), std::ios::binary);
      return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    const std::string name = std::filesystem::path(file).filename().string();
    for (double fraction : {0.05, 0.5, 0.7}) {  // tum_rabbit's geometry ends at 77%
      writeText(path(name), data.substr(0, static_cast<std::size_t>(data.size() * fraction)));
      try {
        loadMesh(path(name));
        ADD_FAILURE() << "truncated at " << fraction << " loaded without error";
      } catch (const FileFormatException& e) {
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      }
    }
  }
}

TEST_F(MeshIOFiles, GarbageAndEmptyFilesFail) {
  std::string garbage;
  for (int i = 0; i < 4096; ++i) garbage.push_back(static_cast<char>((i * 7919) % 251));
  for (const char* ext : {"ply", "off", "obj", "stl", "vtk", "pcd"}) {
    SCOPED_TRACE(ext);
    for (const std::string& content : {garbage, std::string()}) {
      writeText(path(std::string("bad.") + ext), content);
      EXPECT_THROW(loadMesh(path(std::string("bad.") + ext)), FileFormatException);
    }
  }
  EXPECT_THROW(loadMesh(path("missing.ply")), FileFormatException);
  EXPECT_THROW(loadMesh(path("file.xyz")), FileFormatException);
  writeText(path("bad_header.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty quux x\nend_header\n1\n");
  EXPECT_THROW(loadMesh(path("bad_header.ply")), FileFormatException);
}

TEST_F(MeshIOFiles, FacesOfManyCornersAndLongFileNamesAreWritten) {
  pcl::PolygonMesh mesh = makeMesh(Eigen::Matrix3Xd::Random(3, 300), {{0, 1, 2}});
  pcl::Vertices huge;
  for (int i = 0; i < 300; ++i) huge.vertices.push_back(i);
  mesh.polygons.push_back(huge);  // more corners than PLY's usual uchar count can hold
  const std::string long_name = std::string(246, 'n') + ".ply";  // 250 bytes: legal
  for (PlyEncoding encoding : {PlyEncoding::Binary, PlyEncoding::Ascii}) {
    saveMesh(path(long_name), mesh, {encoding});
    const pcl::PolygonMesh back = loadMesh(path(long_name));
    ASSERT_EQ(back.polygons.size(), 2u);
    EXPECT_EQ(back.polygons[1].vertices, huge.vertices);
    EXPECT_EQ(back.polygons[0].vertices.size(), 3u);
  }
}

TEST_F(MeshIOFiles, FailedSaveLeavesNoFile) {
  const pcl::PolygonMesh mesh = makeMesh(Eigen::Matrix3Xd::Zero(3, 3), {{0, 1, 2}});
  EXPECT_THROW(saveMesh(path("out.xyz"), mesh), FileFormatException);
  EXPECT_THROW(saveMesh(path("no/such/folder/out.ply"), mesh), FileFormatException);
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

TEST_F(MeshIOFiles, AnInterruptDuringAWriteLeavesNoTemporaryAndNoOutput) {
  for (const int signal_number : {SIGINT, SIGTERM}) {
    const pid_t child = fork();
    if (child == 0) {
      AtomicFile::removeUncommittedFilesOnInterrupt();
      AtomicFile file(path("out.ply"));
      writeBytes(file.temporaryPath(), "half of a file");
      std::raise(signal_number);  // as a Ctrl-C in the middle of the write
      _exit(0);
    }
    int status = 0;
    waitpid(child, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << status;
    EXPECT_TRUE(std::filesystem::is_empty(dir_));
  }
}

TEST_F(MeshIOFiles, AFullDiskIsAnErrorAndLeavesNoFile) {
  // A file-size limit makes writes fail as a full disk does (EFBIG instead of ENOSPC).
  const pid_t child = fork();
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit{4096, 4096};
    setrlimit(RLIMIT_FSIZE, &limit);
    const pcl::PolygonMesh horse = loadMesh(sharedData("meshes/horse.ply"));
    int failures = 0;
    for (const char* name : {"out.ply", "out.pcd"}) {
      try {
        saveMesh(path(name), horse);
      } catch (const FileFormatException&) {
        ++failures;
      }
    }
    _exit(failures);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2) << "both writers must report the failed write";
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

// Binary PLY faces are read in blocks of rows on several threads: faces of every size (including
// none) across many blocks must come back as written, in either byte order (big-endian goes
// through the general reader, value by value).
TEST_F(MeshIOFiles, BinaryPlyFacesOfMixedSizesReadAsWrittenInBothByteOrders) {
  std::mt19937 random(12);
  std::vector<std::vector<std::int32_t>> faces(20011);
  for (auto& face : faces) {
    face.resize(random() % 7);
    for (auto& corner : face) corner = static_cast<std::int32_t>(random() % 5);
  }
  for (const bool big_endian : {false, true}) {
    SCOPED_TRACE(big_endian ? "big-endian" : "little-endian");
    const auto put = [&](std::string& data, auto value) {
      std::string bytes(sizeof(value), '\0');
      std::memcpy(bytes.data(), &value, sizeof(value));
      if (big_endian) std::reverse(bytes.begin(), bytes.end());
      data += bytes;
    };
    std::string data = std::string("ply\nformat binary_") + (big_endian ? "big" : "little") +
                       "_endian 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                       "property float z\nelement face " +
                       std::to_string(faces.size()) +
                       "\nproperty list uchar int vertex_indices\nend_header\n";
    for (int v = 0; v < 15; ++v) put(data, static_cast<float>(v));
    for (const auto& face : faces) {
      put(data, static_cast<std::uint8_t>(face.size()));
      for (std::int32_t corner : face) put(data, corner);
    }
    writeText(path("mixed.ply"), data);
    const MeshFile file = readMeshFile(path("mixed.ply"));
    EXPECT_EQ(file.positions.col(4), Eigen::Vector3d(12, 13, 14));
    ASSERT_EQ(file.mesh.polygons.size(), faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f) {
      ASSERT_EQ(file.mesh.polygons[f].vertices,
                std::vector<pcl::index_t>(faces[f].begin(), faces[f].end()))
          << "face " << f;
    }
  }
}

// A process that has used OpenMP and then forks (a test runner, a server handing each file to a
// child): loading in the child must not wait for OpenMP threads the child does not have. The
// parallel loaders are horse.ply's binary faces and an ascii OFF of 80,000 lines.
TEST_F(MeshIOFiles, LoadingInAChildForkedAfterOpenMPFinishes) {
  {
    std::ofstream off(path("grid.off"));
    const int side = 200;
    off << "OFF\n" << side * side << " " << 2 * (side - 1) * (side - 1) << " 0\n";
    for (int i = 0; i < side * side; ++i) off << i % side << " " << i / side << " 0\n";
    for (int r = 0; r + 1 < side; ++r) {
      for (int c = 0; c + 1 < side; ++c) {
        const int v = r * side + c;
        off << "3 " << v << " " << v + 1 << " " << v + side << "\n3 " << v + 1 << " "
            << v + side + 1 << " " << v + side << "\n";
      }
    }
  }
  // This process starts OpenMP's thread team, as a test runner or a server may have.
#pragma omp parallel
  {}
  const pid_t child = fork();
  if (child == 0) {
    alarm(120);  // a hang becomes a SIGALRM death (ample under the sanitizers' -O1)
    const bool loaded = loadMesh(sharedData("meshes/horse.ply")).polygons.size() == 96966 &&
                        loadMesh(path("grid.off")).polygons.size() == 2 * 199 * 199;
    _exit(loaded ? 0 : 1);
  }
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "child status " << status;
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
