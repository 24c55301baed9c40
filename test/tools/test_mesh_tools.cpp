// pcl_ddg_normals, pcl_ddg_curvature and pcl_ddg_render as a user runs them: every shared mesh,
// every option, and bad input (one error line, non-zero exit, no output file).
#include <gtest/gtest.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <cmath>
#include <cstdio>

#include <stb_image.h>

#include "analytic_surfaces.h"
#include "data_catalogue.h"
#include "estimator_support.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

class MeshTools : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

TEST_F(MeshTools, NormalsOnEverySharedMeshAreUnitWhereValid) {
  for (const SharedMesh& mesh : sharedMeshes()) {
    const char* file = mesh.path;
    SCOPED_TRACE(file);
    const ToolRun run =
        runTool(PCL_DDG_NORMALS_TOOL, sharedData(file) + " " + path("out.ply") + " -method angle");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const pcl::PolygonMesh out = loadMesh(path("out.ply"));
    const MeshTopology t(out);
    const Eigen::VectorXd nx = vertexScalarField(out.cloud, "nx"),
                          ny = vertexScalarField(out.cloud, "ny"),
                          nz = vertexScalarField(out.cloud, "nz");
    int invalid = 0;
    for (Eigen::Index i = 0; i < nx.size(); ++i) {
      const double norm = std::sqrt(nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i]);
      if (std::isnan(norm)) {
        ++invalid;
        continue;
      }
      ASSERT_NEAR(norm, 1.0, 1e-6);
    }
    EXPECT_GE(invalid, mesh.unreferenced_vertices);
    EXPECT_EQ(static_cast<int>(out.polygons.size()), mesh.faces);
  }
}

TEST_F(MeshTools, CurvatureOnEverySharedMeshWritesAllFields) {
  for (const SharedMesh& mesh : sharedMeshes()) {
    const char* file = mesh.path;
    SCOPED_TRACE(file);
    const ToolRun run =
        runTool(PCL_DDG_CURVATURE_TOOL, sharedData(file) + " " + path("out.ply") + " -color mean");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const pcl::PolygonMesh out = loadMesh(path("out.ply"));
    for (const char* field :
         {"mean_curvature", "gauss_curvature", "k1", "k2", "vertex_area", "red"}) {
      EXPECT_TRUE(hasVertexField(out.cloud, field)) << field;
    }
    const Eigen::VectorXd k1 = vertexScalarField(out.cloud, "k1"),
                          k2 = vertexScalarField(out.cloud, "k2");
    for (Eigen::Index i = 0; i < k1.size(); ++i) {
      if (!std::isnan(k1[i])) ASSERT_GE(k1[i], k2[i]);
    }
  }
}

TEST_F(MeshTools, CurvatureOfASphereFileIsItsInverseRadius) {
  const SurfaceSample sphere = makeIcosphere(4, 2.0);
  const pcl::PolygonMesh mesh = polygonMeshOf(sphere);
  saveMesh(path("sphere.ply"), mesh);
  for (const char* area : {"mixed", "voronoi", "barycentric"}) {
    const ToolRun run = runTool(PCL_DDG_CURVATURE_TOOL, path("sphere.ply") + " " + path("k.ply") +
                                                            " -precision double -area " + area);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const pcl::PolygonMesh out = loadMesh(path("k.ply"));
    EXPECT_NEAR(vertexScalarField(out.cloud, "mean_curvature").mean(), 0.5, 1e-3) << area;
    EXPECT_NEAR((vertexScalarField(out.cloud, "gauss_curvature").array() *
                 vertexScalarField(out.cloud, "vertex_area").array())
                    .sum(),
                4 * 3.14159265358979323846, 1e-6);
  }
}

TEST_F(MeshTools, BadInputGivesOneLineNonZeroExitAndNoOutput) {
  writeText(path("nan.obj"), "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  writeText(path("range.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  writeText(path("cloud.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  writeText(path("garbage.ply"),
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");
  for (const char* tool : {PCL_DDG_NORMALS_TOOL, PCL_DDG_CURVATURE_TOOL}) {
    for (const char* input : {"nan.obj", "range.obj", "garbage.ply", "missing.ply"}) {
      SCOPED_TRACE(std::string(tool) + " " + input);
      const ToolRun run = runTool(tool, path(input) + " " + path("out.ply"));
      EXPECT_EQ(run.exit_code, 1);
      EXPECT_NE(run.err.find(": error: "), std::string::npos) << run.err;
      EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
    }
    EXPECT_EQ(
        runTool(tool, sharedData("meshes/cow.off") + " " + path("out.ply") + " -bogus 1").exit_code,
        2);
    EXPECT_EQ(runTool(tool, sharedData("meshes/cow.off") + " " + path("out.xyz")).exit_code, 2);
    EXPECT_EQ(runTool(tool, sharedData("meshes/cow.off")).exit_code, 2);
  }
  EXPECT_EQ(runTool(PCL_DDG_NORMALS_TOOL,
                    sharedData("meshes/cow.off") + " " + path("o.ply") + " -method area -epsilon 1")
                .exit_code,
            2);
  EXPECT_EQ(runTool(PCL_DDG_CURVATURE_TOOL,
                    sharedData("meshes/cow.off") + " " + path("o.ply") + " -area heron")
                .exit_code,
            2);
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

TEST_F(MeshTools, FaceMethodsOnACloudOrBFSWithoutAMeshAreUsageErrors) {
  writeText(path("cloud.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.1\n");
  for (const char* options :
       {" -method area", " -method mean_curvature", " -method pca -neighbours rings"}) {
    const ToolRun run =
        runTool(PCL_DDG_NORMALS_TOOL, path("cloud.obj") + " " + path("out.ply") + options);
    EXPECT_EQ(run.exit_code, 2) << options;
    EXPECT_NE(run.err.find("point cloud"), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
  }
  EXPECT_EQ(
      runTool(PCL_DDG_CURVATURE_TOOL, path("cloud.obj") + " " + path("out.ply") + " -method cotan")
          .exit_code,
      2);
  for (const char* options :
       {" -k 2", " -radius abc", " -radius -1", " -radius 2.5q", " -method area -k 5"}) {
    EXPECT_EQ(runTool(PCL_DDG_NORMALS_TOOL,
                      sharedData("meshes/cow.off") + " " + path("out.ply") + options)
                  .exit_code,
              2)
        << options;
  }
}

TEST_F(MeshTools, OrganizedFramesUseTheGridAndStayOrganized) {
  const std::string frame = sharedData("clouds/office1.pcd");
  for (const char* options : {"", " -method quadric", " -orient mst", " -max_depth_jump 0.05"}) {
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, frame + " " + path("out.pcd") + options);
    ASSERT_EQ(run.exit_code, 0) << options << run.err;
    EXPECT_NE(run.err.find("pixel grid"), std::string::npos) << run.err;
    pcl::PCLPointCloud2 in, out;
    ASSERT_EQ(pcl::io::loadPCDFile(frame, in), 0);
    ASSERT_EQ(pcl::io::loadPCDFile(path("out.pcd"), out), 0);
    EXPECT_EQ(out.width, 640u) << options;
    EXPECT_EQ(out.height, 480u) << options;
    pcl::PointCloud<pcl::PointNormal> points;
    pcl::fromPCLPointCloud2(out, points);
    int holes = 0;
    for (const auto& p : points) {
      if (std::isfinite(p.x)) continue;
      ++holes;
      EXPECT_FALSE(std::isfinite(p.normal_x)) << "a hole was filled";
    }
    EXPECT_GT(holes, 50000);
  }
  std::filesystem::remove(path("out.pcd"));
  // The normals as an image of the frame.
  ASSERT_EQ(runTool(PCL_DDG_NORMALS_TOOL,
                    frame + " " + path("out.pcd") + " -normal_map " + path("normals.png"))
                .exit_code,
            0);
  std::FILE* png = std::fopen(path("normals.png").c_str(), "rb");
  ASSERT_NE(png, nullptr);
  unsigned char header[24] = {};
  ASSERT_EQ(std::fread(header, 1, sizeof header, png), sizeof header);
  std::fclose(png);
  EXPECT_EQ((header[16] << 24 | header[17] << 16 | header[18] << 8 | header[19]), 640);
  EXPECT_EQ((header[20] << 24 | header[21] << 16 | header[22] << 8 | header[23]), 480);
  std::filesystem::remove(path("out.pcd"));
  // The grid needs an organized cloud; -max_depth_jump is for the grid; -orient mesh for meshes.
  for (const std::string& options :
       {sharedData("clouds/bun0.pcd") + " " + path("out.pcd") + " -neighbours grid",
        frame + " " + path("out.pcd") + " -neighbours kdtree -max_depth_jump 0.1",
        frame + " " + path("out.pcd") + " -max_depth_jump 0",
        frame + " " + path("out.pcd") + " -orient mesh",
        sharedData("clouds/bun0.pcd") + " " + path("out.pcd") + " -normal_map " + path("n.png"),
        sharedData("meshes/cow.off") + " " + path("out.ply") + " -method area -orient mst"}) {
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, options);
    EXPECT_EQ(run.exit_code, 2) << options;
    EXPECT_FALSE(std::filesystem::exists(path("out.pcd"))) << options;
    EXPECT_FALSE(std::filesystem::exists(path("out.ply"))) << options;
    std::filesystem::remove(path("out.pcd"));
  }
}

TEST_F(MeshTools, CompareNeighbourhoodsOnAnOrganizedFrame) {
  // Pixel grid against kd-tree; the output stays organized and carries both fields.
  const ToolRun run = runTool(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL,
                              sharedData("clouds/office1.pcd") + " " + path("out.pcd") + " -k 49");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("pixel grid"), std::string::npos) << run.err;
  pcl::PCLPointCloud2 out;
  ASSERT_EQ(pcl::io::loadPCDFile(path("out.pcd"), out), 0);
  EXPECT_EQ(out.width, 640u);
  EXPECT_EQ(out.height, 480u);
  EXPECT_TRUE(vertexScalarField(out, "angle_difference").size() == 307200);
  EXPECT_TRUE(vertexScalarField(out, "overlap").size() == 307200);
  // An unorganized cloud has no topology to compare.
  EXPECT_EQ(runTool(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL,
                    sharedData("clouds/bun0.pcd") + " " + path("bun.pcd"))
                .exit_code,
            1);
}

TEST_F(MeshTools, SpanningTreeOrientationReportsItsFlips) {
  // horse.ply's faces are wound inwards: PCA normals oriented like them point in; the tree,
  // seeded up at the highest point, turns (nearly) all of them out.
  const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, sharedData("meshes/horse.ply") + " " +
                                                        path("out.ply") + " -orient mst");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("in 1 components"), std::string::npos) << run.err;
  const MeshFile in = readMeshFile(sharedData("meshes/horse.ply"));
  const MeshFile out = readMeshFile(path("out.ply"));
  Eigen::Matrix3Xd normals(3, out.positions.cols());
  normals.row(0) = vertexScalarField(out.mesh.cloud, "nx").transpose();
  normals.row(1) = vertexScalarField(out.mesh.cloud, "ny").transpose();
  normals.row(2) = vertexScalarField(out.mesh.cloud, "nz").transpose();
  const Eigen::Vector3d centre = in.positions.rowwise().mean();
  // The highest point's normal points up, and most normals point away from the centre.
  Eigen::Index top = 0;
  in.positions.row(2).maxCoeff(&top);
  EXPECT_GT(normals(2, top), 0.5);
  int outward = 0;
  for (Eigen::Index v = 0; v < normals.cols(); ++v)
    outward += normals.col(v).dot(in.positions.col(v) - centre) > 0.0;
  EXPECT_GT(outward, 0.8 * normals.cols());
}

TEST_F(MeshTools, NormalMethodsAndPcdOutput) {
  for (const char* method : {"uniform", "area", "angle", "mean_curvature"}) {
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, sharedData("meshes/bumpy.off") + " " +
                                                          path("n.pcd") + " -method " + method);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("[done, "), std::string::npos);
    const pcl::PolygonMesh out = loadMesh(path("n.pcd"));
    EXPECT_EQ(out.cloud.width, 1250u);
    EXPECT_TRUE(hasVertexField(out.cloud, "normal_z")) << "PCL's names in a PCD";
  }
}

// Unit normals wherever they are finite; returns how many are not.
int checkUnitNormals(const pcl::PCLPointCloud2& cloud, const char* x, const char* y,
                     const char* z) {
  const Eigen::VectorXd nx = vertexScalarField(cloud, x), ny = vertexScalarField(cloud, y),
                        nz = vertexScalarField(cloud, z);
  int invalid = 0;
  for (Eigen::Index i = 0; i < nx.size(); ++i) {
    const double norm = std::sqrt(nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i]);
    if (std::isnan(norm)) {
      ++invalid;
    } else {
      EXPECT_NEAR(norm, 1.0, 1e-5);
    }
  }
  return invalid;
}

TEST_F(MeshTools, FittedNormalsOnEverySharedMesh) {
  for (const SharedMesh& mesh : sharedMeshes()) {
    const char* file = mesh.path;
    for (const char* options :
         {" -method pca", " -method quadric -neighbours kdtree -radius 2.5h"}) {
      SCOPED_TRACE(std::string(file) + options);
      const ToolRun run =
          runTool(PCL_DDG_NORMALS_TOOL, sharedData(file) + " " + path("out.ply") + options);
      ASSERT_EQ(run.exit_code, 0) << run.err;
      const pcl::PolygonMesh out = loadMesh(path("out.ply"));
      const int invalid = checkUnitNormals(out.cloud, "nx", "ny", "nz");
      EXPECT_LT(invalid, static_cast<int>(out.cloud.width) / 10);
      EXPECT_TRUE(hasVertexField(out.cloud, "curvature"));
    }
  }
}

TEST_F(MeshTools, FittedNormalsOnEverySharedCloud) {
  for (const SharedCloud& cloud : sharedClouds()) {
    const char* file = cloud.path;
    SCOPED_TRACE(file);
    const ToolRun run =
        runTool(PCL_DDG_NORMALS_TOOL, sharedData(file) + " " + path("out.pcd") + " -k 12");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("[done, "), std::string::npos);
    const pcl::PolygonMesh out = loadMesh(path("out.pcd"));
    const pcl::PolygonMesh input = loadMesh(sharedData(file));
    const Eigen::Matrix3Xd in = vertexPositions(input.cloud, NonFinitePolicy::Keep);
    EXPECT_EQ(static_cast<Eigen::Index>(out.cloud.width) * out.cloud.height, in.cols())
        << "one normal per point";
    EXPECT_EQ(out.cloud.height, input.cloud.height) << "organized stays organized";
    const int invalid = checkUnitNormals(out.cloud, "normal_x", "normal_y", "normal_z");
    EXPECT_GE(invalid, findNonFiniteVertices(in).count);
    EXPECT_TRUE(hasVertexField(out.cloud, "curvature"));
  }
  // The organized range grid (a PLY without faces) and the quadric with a radius in spacing units.
  const ToolRun run =
      runTool(PCL_DDG_NORMALS_TOOL, sharedData("range/bun000.ply") + " " + path("range.ply") +
                                        " -method quadric -radius 3h");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  checkUnitNormals(loadMesh(path("range.ply")).cloud, "nx", "ny", "nz");
}

TEST_F(MeshTools, TheFormerNeighbourhoodSpellingsGiveTheSameBytes) {
  // -neighbours bfs and knn (before rings and kdtree) keep working, as the same neighbourhoods.
  saveMesh(path("sphere.ply"), polygonMeshOf(makeIcosphere(3, 1.0)));
  const auto bytesOf = [&](const std::string& neighbours) {
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, path("sphere.ply") + " " + path("n.ply") +
                                                          " -method pca -neighbours " + neighbours);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    std::ifstream in(path("n.ply"), std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string rings = bytesOf("rings"), kdtree = bytesOf("kdtree");
  EXPECT_NE(rings, kdtree);
  EXPECT_EQ(bytesOf("bfs"), rings);
  EXPECT_EQ(bytesOf("knn"), kdtree);
  EXPECT_EQ(runTool(PCL_DDG_NORMALS_TOOL,
                    path("sphere.ply") + " " + path("n.ply") + " -method pca -neighbours octree")
                .exit_code,
            2);
}

TEST_F(MeshTools, QuadricCurvatureOfASphereFileIsItsInverseRadius) {
  const SurfaceSample sphere = makeIcosphere(4, 2.0);
  const pcl::PolygonMesh mesh = polygonMeshOf(sphere);
  saveMesh(path("sphere.ply"), mesh);
  for (const char* neighbours : {"rings", "kdtree"}) {
    const ToolRun run =
        runTool(PCL_DDG_CURVATURE_TOOL, path("sphere.ply") + " " + path("k.ply") +
                                            " -method quadric -color k1 -neighbours " + neighbours);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const pcl::PolygonMesh out = loadMesh(path("k.ply"));
    // Oriented by the faces (outward) with either neighbourhood: positive curvature. A quadric
    // fits a sphere to O(h^2): measured +0.73% with 20 neighbours at this level.
    EXPECT_NEAR(vertexScalarField(out.cloud, "mean_curvature").mean(), 0.5, 0.5e-2) << neighbours;
    EXPECT_NEAR(vertexScalarField(out.cloud, "gauss_curvature").mean(), 0.25, 0.25 * 2e-2)
        << neighbours;
    for (const char* field : {"k1", "k2", "k1_direction_x", "nx", "red"}) {
      EXPECT_TRUE(hasVertexField(out.cloud, field)) << field;
    }
  }
}

TEST_F(MeshTools, CompareNeighbourhoodsShowsAThinTwoSheetSurface) {
  const SurfaceSample sheets = makeTwoSheets(1.5 / 12);
  const pcl::PolygonMesh mesh = polygonMeshOf(sheets);
  saveMesh(path("sheets.ply"), mesh);
  const ToolRun run = runTool(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL,
                              path("sheets.ply") + " " + path("cmp.ply") + " -k 16");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  double over5 = -1, over30 = -1;
  const auto at = run.out.find("over 5 degrees: ");
  ASSERT_NE(at, std::string::npos) << run.out;
  ASSERT_EQ(std::sscanf(run.out.c_str() + at, "over 5 degrees: %lf%%, over 30 degrees: %lf%%",
                        &over5, &over30),
            2);
  EXPECT_GT(over30, 10.0) << run.out;
  const pcl::PolygonMesh out = loadMesh(path("cmp.ply"));
  for (const char* field : {"angle_difference", "overlap", "red"})
    EXPECT_TRUE(hasVertexField(out.cloud, field));
  EXPECT_LT(vertexScalarField(out.cloud, "overlap").mean(), 0.6);

  const ToolRun scan =
      runTool(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL, sharedData("meshes/bun_zipper.ply") + " " +
                                                       path("bz.ply") + " -method quadric -k 20");
  ASSERT_EQ(scan.exit_code, 0) << scan.err;
  EXPECT_NE(scan.out.find("mean Jaccard"), std::string::npos);
  const ToolRun cloud = runTool(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL,
                                sharedData("clouds/bun0.pcd") + " " + path("c.ply"));
  EXPECT_EQ(cloud.exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(path("c.ply")));
}

TEST_F(MeshTools, NormalsReplaceTheInputsOwnAndAreNeverWrittenTwice) {
  // bun0.pcd carries PCL's normal_x/y/z + curvature, horse.ply its nx/ny/nz: whatever the output
  // format, the input's triple is replaced in its own naming, and no second triple appears.
  const auto names = [](const std::string& file) {
    std::vector<std::string> n;
    for (const auto& f : loadMesh(file).cloud.fields) n.push_back(f.name);
    return n;
  };
  const auto count = [](const std::vector<std::string>& n, const std::string& name) {
    return std::count(n.begin(), n.end(), name);
  };
  const std::string bunny = sharedData("clouds/bun0.pcd"), horse = sharedData("meshes/horse.ply");
  ASSERT_EQ(runTool(PCL_DDG_NORMALS_TOOL, bunny + " " + path("bunny.ply")).exit_code, 0);
  ASSERT_EQ(runTool(PCL_DDG_NORMALS_TOOL, horse + " " + path("horse.pcd")).exit_code, 0);
  ASSERT_EQ(
      runTool(PCL_DDG_NORMALS_TOOL, horse + " " + path("horse_pca.pcd") + " -method pca").exit_code,
      0);
  const auto b = names(path("bunny.ply"));
  EXPECT_EQ(count(b, "normal_x") + count(b, "nx"), 1);
  EXPECT_EQ(count(b, "normal_x"), 1) << "bun0's own naming";
  EXPECT_EQ(count(b, "curvature"), 1);
  for (const char* out : {"horse.pcd", "horse_pca.pcd"}) {
    const auto h = names(path(out));
    EXPECT_EQ(count(h, "nx"), 1) << out;
    EXPECT_EQ(count(h, "normal_x"), 0) << out;
  }
}

TEST_F(MeshTools, CloudNormalsFaceTheViewpointGivenOrInTheFile) {
  // Aerial LiDAR in UTM coordinates, its VIEWPOINT at the origin (far below and to the side):
  // towards it, a large share of the ground's normals point down; towards a point above the
  // scan, all but the steepest point up. The viewpoint given is written to the output.
  const std::string terrain = sharedData("clouds/terrain_CSite1_red2-utm.pcd");
  const auto upShare = [&](const std::string& out) {
    const Eigen::Matrix3Xd n = [&] {
      const pcl::PolygonMesh m = loadMesh(out);
      Eigen::Matrix3Xd values(3, m.cloud.width * m.cloud.height);
      values.row(0) = vertexScalarField(m.cloud, "normal_x").transpose();
      values.row(1) = vertexScalarField(m.cloud, "normal_y").transpose();
      values.row(2) = vertexScalarField(m.cloud, "normal_z").transpose();
      return values;
    }();
    return (n.row(2).array() > 0.0).cast<double>().mean();
  };
  ASSERT_EQ(runTool(PCL_DDG_NORMALS_TOOL, terrain + " " + path("origin.pcd")).exit_code, 0);
  const ToolRun above = runTool(
      PCL_DDG_NORMALS_TOOL, terrain + " " + path("above.pcd") + " -viewpoint 512600,5403580,10000");
  ASSERT_EQ(above.exit_code, 0) << above.err;
  const double towards_origin = upShare(path("origin.pcd")),
               towards_above = upShare(path("above.pcd"));
  std::printf(
      "terrain normals pointing up: %.1f%% towards the file's VIEWPOINT, %.2f%% towards a "
      "point above\n",
      100 * towards_origin, 100 * towards_above);
  EXPECT_GT(towards_above, 0.99);
  EXPECT_LT(towards_origin, 0.9);
  SensorPose pose;
  loadMesh(path("above.pcd"), &pose);
  EXPECT_EQ(pose.origin, Eigen::Vector3d::Zero()) << "the input's VIEWPOINT is kept in the output";
}

TEST_F(MeshTools, RenderMakesAPicture) {
  const ToolRun run = runTool(PCL_DDG_RENDER_TOOL,
                              sharedData("meshes/cow.off") + " " + path("cow.png") + " -size 64");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_GT(std::filesystem::file_size(path("cow.png")), 100u);
  const ToolRun missing = runTool(PCL_DDG_RENDER_TOOL, sharedData("meshes/cow.off") + " " +
                                                           path("cow.png") + " -field nothing");
  EXPECT_EQ(missing.exit_code, 1);
  // The error names what there is to choose from.
  EXPECT_NE(missing.err.find("no 'nothing' field (it has: x y z)"), std::string::npos)
      << missing.err;
  // A field: coloured between its 2nd and 98th percentiles, which the tool says, with a colour
  // bar beside the picture (a wider image).
  ASSERT_EQ(runTool(PCL_DDG_CURVATURE_TOOL,
                    sharedData("meshes/cow.off") + " " + path("k.ply") + " -precision double")
                .exit_code,
            0);
  const ToolRun field =
      runTool(PCL_DDG_RENDER_TOOL, path("k.ply") + " " + path("k.png") + " -field k1 -size 200");
  ASSERT_EQ(field.exit_code, 0) << field.err;
  std::vector<double> k1;
  const pcl::PolygonMesh curvatures = loadMesh(path("k.ply"));
  const Eigen::VectorXd values = vertexScalarField(curvatures.cloud, "k1");
  for (Eigen::Index i = 0; i < values.size(); ++i)
    if (std::isfinite(values[i])) k1.push_back(values[i]);
  std::sort(k1.begin(), k1.end());
  const auto at = [&](double percent) {
    return k1[static_cast<std::size_t>(std::lround(percent / 100.0 * (k1.size() - 1)))];
  };
  const double end = std::max(std::abs(at(2.0)), std::abs(at(98.0)));  // diverging: symmetric
  char expected[96];
  std::snprintf(expected, sizeof expected, "k1 coloured from %g to %g (2nd and 98th", -end, end);
  EXPECT_NE(field.err.find(expected), std::string::npos) << field.err << "\nexpected " << expected;
  int width = 0, height = 0, channels = 0;
  ASSERT_TRUE(stbi_info(path("k.png").c_str(), &width, &height, &channels));
  EXPECT_EQ(height, 200);
  EXPECT_GT(width, 200 + 100);
  // Clouds are drawn too (splats in the cloud's own colours).
  const ToolRun cloud = runTool(PCL_DDG_RENDER_TOOL, sharedData("clouds/office1.pcd") + " " +
                                                         path("office.png") + " -size 64");
  ASSERT_EQ(cloud.exit_code, 0) << cloud.err;
  EXPECT_GT(std::filesystem::file_size(path("office.png")), 100u);
  // A full disk (here a 16 KiB file-size limit, SIGXFSZ ignored; the OpenMP runtime needs a few
  // KiB for itself) is an error, not an empty PNG.
  const ToolRun full =
      runTool(std::string("trap '' XFSZ; ulimit -f 16; ") + PCL_DDG_RENDER_TOOL,
              sharedData("meshes/cow.off") + " " + path("full.png") + " -size 1024");
  EXPECT_EQ(full.exit_code, 1) << full.err;
  EXPECT_NE(full.err.find("pcl_ddg_render: error: cannot write"), std::string::npos) << full.err;
  EXPECT_FALSE(std::filesystem::exists(path("full.png")));
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
