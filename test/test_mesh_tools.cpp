// pcl_ddg_normals, pcl_ddg_curvature and pcl_ddg_render as a user runs them: every shared mesh,
// every option, and bad input (one error line, non-zero exit, no output file).
#include <gtest/gtest.h>

#include <filesystem>

#include "analytic_surfaces.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

const char* kSharedMeshes[] = {"bumpy.off",
                               "bun045_rangegrid_tri.ply",
                               "bun_zipper.ply",
                               "bun_zipper_res3.ply",
                               "bun_zipper_res4.ply",
                               "bunny.off",
                               "cow.off",
                               "horse.ply",
                               "igea.ply",
                               "rocker-arm.off",
                               "tum_rabbit.vtk"};

class MeshTools : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

TEST_F(MeshTools, NormalsOnEverySharedMeshAreUnitWhereValid) {
  for (const char* file : kSharedMeshes) {
    SCOPED_TRACE(file);
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, sharedData(std::string("meshes/") + file) +
                                                          " " + path("out.ply") + " -method angle");
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
    EXPECT_GE(invalid, t.counts().unreferenced_vertices);
    EXPECT_EQ(out.polygons.size(),
              loadMesh(sharedData(std::string("meshes/") + file)).polygons.size());
  }
}

TEST_F(MeshTools, CurvatureOnEverySharedMeshWritesAllFields) {
  for (const char* file : kSharedMeshes) {
    SCOPED_TRACE(file);
    const ToolRun run = runTool(PCL_DDG_CURVATURE_TOOL, sharedData(std::string("meshes/") + file) +
                                                            " " + path("out.ply") + " -color mean");
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
  pcl::PolygonMesh mesh = makeMesh(sphere.points, {});
  for (Eigen::Index t = 0; t < sphere.triangles.cols(); ++t) {
    pcl::Vertices v;
    v.vertices = {sphere.triangles(0, t), sphere.triangles(1, t), sphere.triangles(2, t)};
    mesh.polygons.push_back(v);
  }
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
    for (const char* input : {"nan.obj", "range.obj", "cloud.obj", "garbage.ply", "missing.ply"}) {
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

TEST_F(MeshTools, NormalMethodsAndPcdOutput) {
  for (const char* method : {"uniform", "area", "angle", "mean_curvature"}) {
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, sharedData("meshes/bumpy.off") + " " +
                                                          path("n.pcd") + " -method " + method);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("[done, "), std::string::npos);
    const pcl::PolygonMesh out = loadMesh(path("n.pcd"));
    EXPECT_EQ(out.cloud.width, 1250u);
    EXPECT_TRUE(hasVertexField(out.cloud, "nz"));
  }
}

TEST_F(MeshTools, RenderMakesAPicture) {
  const ToolRun run = runTool(PCL_DDG_RENDER_TOOL,
                              sharedData("meshes/cow.off") + " " + path("cow.png") + " -size 64");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_GT(std::filesystem::file_size(path("cow.png")), 100u);
  EXPECT_EQ(runTool(PCL_DDG_RENDER_TOOL,
                    sharedData("meshes/cow.off") + " " + path("cow.png") + " -field nothing")
                .exit_code,
            1);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
