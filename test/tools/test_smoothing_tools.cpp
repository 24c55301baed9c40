// pcl_ddg_smooth, pcl_ddg_smooth_organized and pcl_ddg_curvature -smooth as a user runs them.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/surface/mesh_smoothing.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

class SmoothingTools : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void expectNoLeftovers() const {
    for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
      EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
    }
  }
  std::string dir_;
};

TEST_F(SmoothingTools, SmoothSharedMeshesBothSchemesKeepTheMeshAndPreserveVolume) {
  for (const char* file : {"cow.off", "bunny.off", "bun_zipper_res4.ply", "horse.ply"}) {
    SCOPED_TRACE(file);
    const std::string input = sharedData(std::string("meshes/") + file);
    const MeshFile original_file = readMeshFile(input);
    const pcl::PolygonMesh& original = original_file.mesh;
    const MeshTopology topology(original);
    const Eigen::Matrix3Xd& before = original_file.positions;
    for (const char* options : {"", "-method explicit -iterations 20",
                                "-lambda_dt 5 -weights uniform", "-method taubin -iterations 20"}) {
      SCOPED_TRACE(options);
      const ToolRun run =
          runTool(PCL_DDG_SMOOTH_TOOL, input + " " + path("out.ply") + " " + options);
      ASSERT_EQ(run.exit_code, 0) << run.err;
      EXPECT_NE(run.err.find("Smoothing [done"), std::string::npos) << run.err;
      const pcl::PolygonMesh out = loadMesh(path("out.ply"));
      ASSERT_EQ(out.polygons.size(), original.polygons.size());
      const Eigen::Matrix3Xd after = vertexPositions(out.cloud);
      ASSERT_EQ(after.cols(), before.cols());
      EXPECT_TRUE(after.allFinite());
      EXPECT_GT((after - before).norm(), 0.0);
    }
    if (topology.counts().boundary_edges == 0) {
      const ToolRun run = runTool(PCL_DDG_SMOOTH_TOOL, input + " " + path("vol.ply") +
                                                           " -lambda_dt 3 -iterations 2 -preserve "
                                                           "volume -precision double");
      ASSERT_EQ(run.exit_code, 0) << run.err;
      const MeshFile smoothed = readMeshFile(path("vol.ply"));
      EXPECT_EQ(smoothed.coordinate_precision, FieldPrecision::Double);
      const Eigen::Matrix3Xd& after = smoothed.positions;
      EXPECT_NEAR(enclosedVolume(topology, after) / enclosedVolume(topology, before), 1.0, 1e-9);
    }
  }
  expectNoLeftovers();
}

TEST_F(SmoothingTools, EverySolverGivesTheSameSurfaceAndIsNamed) {
  // One step of h^2 (the default): Automatic iterates. Double coordinates out, so the solvers'
  // agreement is not hidden by float rounding.
  const std::string input = sharedData("meshes/cow.off");
  const auto smoothed = [&](const std::string& solver, const std::string& expected_name) {
    SCOPED_TRACE(solver);
    const ToolRun run = runTool(PCL_DDG_SMOOTH_TOOL,
                                input + " " + path("out.ply") + " -precision double " + solver);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("solver " + expected_name), std::string::npos) << run.err;
    return readMeshFile(path("out.ply")).positions;
  };
  const Eigen::Matrix3Xd automatic = smoothed("", "conjugate gradients (");
  const Eigen::Matrix3Xd cg = smoothed("-solver cg", "conjugate gradients (");
  const Eigen::Matrix3Xd ldlt = smoothed("-solver ldlt", "SimplicialLDLT");
  const Eigen::Matrix3Xd input_positions = readMeshFile(input).positions;
  EXPECT_EQ(automatic, cg);
  EXPECT_GT((ldlt - input_positions).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT((cg - ldlt).cwiseAbs().maxCoeff(), 1e-12);
  if (cholmodAvailable()) {
    const Eigen::Matrix3Xd cholmod = smoothed("-solver cholmod", "CHOLMOD");
    EXPECT_LT((cg - cholmod).cwiseAbs().maxCoeff(), 1e-12);
  }
  expectNoLeftovers();
}

TEST_F(SmoothingTools, ExplicitStepsAboveTheStabilityBoundAreRefusedUnlessAllowed) {
  const std::string cow = sharedData("meshes/cow.off");
  const ToolRun safe =
      runTool(PCL_DDG_SMOOTH_TOOL, cow + " " + path("a.ply") + " -method explicit");
  ASSERT_EQ(safe.exit_code, 0) << safe.err;
  EXPECT_NE(safe.err.find("stability bound"), std::string::npos) << safe.err;
  EXPECT_EQ(safe.err.find("warning"), std::string::npos) << safe.err;
  // The umbrella operator (explicit's default) is stable up to a step of 1, without unit.
  EXPECT_NE(safe.err.find("explicit step 0.5 (averaged by degree); stability bound 1\n"),
            std::string::npos)
      << safe.err;
  const ToolRun refused =
      runTool(PCL_DDG_SMOOTH_TOOL, cow + " " + path("b.ply") + " -method explicit -lambda_dt 1.5");
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("pcl_ddg_smooth: error: the explicit step 1.5 exceeds the stability "
                             "bound 1:"),
            std::string::npos)
      << refused.err;
  EXPECT_FALSE(std::filesystem::exists(path("b.ply")));
  // Cotangent weights over vertex areas: a bound in h^2, a fraction of one on the cow.
  const ToolRun cotan = runTool(PCL_DDG_SMOOTH_TOOL, cow + " " + path("b.ply") +
                                                         " -method explicit -weights cotan "
                                                         "-lambda_dt 1");
  EXPECT_EQ(cotan.exit_code, 2);
  EXPECT_NE(cotan.err.find("error: the explicit step 1 h^2 exceeds the stability bound 0.0"),
            std::string::npos)
      << cotan.err;
  // Taubin: (1 - 0.99 k)(1 + k) at the bound's highest frequency k = 2 is -2.94: refused.
  const ToolRun taubin = runTool(PCL_DDG_SMOOTH_TOOL,
                                 cow + " " + path("b.ply") + " -method taubin -lambda 0.99 -mu -1");
  EXPECT_EQ(taubin.exit_code, 2);
  EXPECT_NE(taubin.err.find("error: the Taubin steps 0.99 and -1 multiply the finest wrinkles the "
                            "stability bound 1 allows by -2.94: the surface would blow up (-method "
                            "implicit"),
            std::string::npos)
      << taubin.err;
  EXPECT_FALSE(std::filesystem::exists(path("b.ply")));
  const ToolRun allowed = runTool(PCL_DDG_SMOOTH_TOOL, cow + " " + path("c.ply") +
                                                           " -method explicit -lambda_dt 1.5 "
                                                           "-iterations 2 -allow_unstable");
  EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
  EXPECT_TRUE(std::filesystem::exists(path("c.ply")));
  EXPECT_NE(allowed.err.find("warning: the steps exceed the stability bound"), std::string::npos)
      << allowed.err;
}

TEST_F(SmoothingTools, AStepThatCollapsesTheScanFailsNamingLambdaDt) {
  // Without the thickness limit, 1e9 h^2 squeezes the cow to a point: exit 1, one line that
  // names the remedy, no output.
  const ToolRun run =
      runTool(PCL_DDG_SMOOTH_TOOL, sharedData("meshes/cow.off") + " " + path("out.ply") +
                                       " -lambda_dt 1e9 -thickness_limit 0");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("pcl_ddg_smooth: error: smoothing iteration 1: the surface collapsed"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("-lambda_dt"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
  // With the volume preserved the remnant would be inflated back into a needle: refused too.
  EXPECT_EQ(runTool(PCL_DDG_SMOOTH_TOOL, sharedData("meshes/cow.off") + " " + path("out.ply") +
                                             " -lambda_dt 1e9 -preserve volume -thickness_limit 0")
                .exit_code,
            1);
  // With it (the default) no vertex smooths for more than half its thickness squared: the cow
  // keeps its shape, and the run says how many vertices it slowed.
  const ToolRun limited = runTool(PCL_DDG_SMOOTH_TOOL, sharedData("meshes/cow.off") + " " +
                                                           path("out.ply") + " -lambda_dt 1e9");
  EXPECT_EQ(limited.exit_code, 0) << limited.err;
  EXPECT_NE(limited.err.find("pcl_ddg_smooth: -thickness_limit 0.5: "), std::string::npos)
      << limited.err;
  EXPECT_NE(limited.err.find(" vertices smoothed for < 90% of the time (inner radius < "),
            std::string::npos)
      << limited.err;
  EXPECT_NE(limited.err.find("slivers (a corner < 1 deg) 0 -> 0"), std::string::npos)
      << limited.err;
  std::filesystem::remove(path("out.ply"));
  for (const char* options :
       {" -thickness_limit -1", " -thickness_limit nan", " -method taubin -thickness_limit 0.5",
        " -method explicit -weights umbrella -thickness_limit 1"}) {
    const ToolRun bad = runTool(PCL_DDG_SMOOTH_TOOL,
                                sharedData("meshes/cow.off") + " " + path("out.ply") + options);
    EXPECT_EQ(bad.exit_code, 2) << options << "\n" << bad.err;
    EXPECT_NE(bad.err.find("pcl_ddg_smooth: error: -thickness_limit "), std::string::npos)
        << options << "\n"
        << bad.err;
  }
  EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
}

TEST_F(SmoothingTools, MeshQualityIsReportedAndAnOpenScanWarnsAboutItsShrinkingBoundary) {
  const std::string scan = sharedData("meshes/bun045_rangegrid_tri.ply");
  const ToolRun free_boundary =
      runTool(PCL_DDG_SMOOTH_TOOL, scan + " " + path("a.ply") + " -lambda_dt 2 -iterations 3");
  ASSERT_EQ(free_boundary.exit_code, 0) << free_boundary.err;
  EXPECT_NE(free_boundary.err.find("smallest angle"), std::string::npos) << free_boundary.err;
  EXPECT_NE(free_boundary.err.find("warning: the free boundary of this open mesh shrank"),
            std::string::npos)
      << free_boundary.err;
  const ToolRun fixed =
      runTool(PCL_DDG_SMOOTH_TOOL,
              scan + " " + path("b.ply") + " -lambda_dt 2 -iterations 3 -fix_boundary");
  ASSERT_EQ(fixed.exit_code, 0) << fixed.err;
  EXPECT_EQ(fixed.err.find("shrank"), std::string::npos) << fixed.err;
  // One triangle with a fixed boundary: nothing to solve for, said so, input written back.
  writeText(path("triangle.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const ToolRun triangle =
      runTool(PCL_DDG_SMOOTH_TOOL, path("triangle.obj") + " " + path("t.ply") + " -fix_boundary");
  ASSERT_EQ(triangle.exit_code, 0) << triangle.err;
  EXPECT_NE(triangle.err.find("no vertex is free to move"), std::string::npos) << triangle.err;
  EXPECT_EQ(vertexPositions(loadMesh(path("t.ply")).cloud),
            vertexPositions(loadMesh(path("triangle.obj")).cloud));
}

TEST_F(SmoothingTools, BadInputAndOptionsGiveOneLineAndNoOutput) {
  writeText(path("nan.obj"), "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  writeText(path("cloud.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  writeText(path("garbage.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1\n");
  for (const char* input : {"nan.obj", "cloud.obj", "garbage.ply", "missing.off"}) {
    SCOPED_TRACE(input);
    const ToolRun run = runTool(PCL_DDG_SMOOTH_TOOL, path(input) + " " + path("out.ply"));
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.err.find("pcl_ddg_smooth: error: "), std::string::npos) << run.err;
  }
  const std::string cow = sharedData("meshes/cow.off");
  for (const char* options : {"-method magic", "-lambda_dt 0", "-iterations 0", "-absolute_time",
                              "-preserve mass", "-bogus", "-area mixed -mass voronoi"}) {
    SCOPED_TRACE(options);
    EXPECT_EQ(runTool(PCL_DDG_SMOOTH_TOOL, cow + " " + path("out.ply") + " " + options).exit_code,
              2);
  }
  // A volume correction on an open scan, or with a fixed boundary: one line, exit 2.
  const ToolRun open = runTool(PCL_DDG_SMOOTH_TOOL, sharedData("meshes/bun_zipper.ply") + " " +
                                                        path("out.ply") + " -preserve volume");
  EXPECT_EQ(open.exit_code, 2);
  EXPECT_NE(open.err.find("closed"), std::string::npos) << open.err;
  EXPECT_EQ(
      runTool(PCL_DDG_SMOOTH_TOOL, cow + " " + path("out.ply") + " -preserve area -fix_boundary")
          .exit_code,
      2);
  EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
  expectNoLeftovers();
}

TEST_F(SmoothingTools, OrganizedCloudKeepsItsGridHolesAndRays) {
  const std::string input = sharedData("clouds/table_scene_mug_stereo_textured.pcd");
  const ToolRun run =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL, input + " " + path("out.pcd") + " -lambda_dt 4");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const pcl::PolygonMesh before = loadMesh(input), after = loadMesh(path("out.pcd"));
  EXPECT_EQ(after.cloud.width, 640u);
  EXPECT_EQ(after.cloud.height, 480u);
  EXPECT_EQ(after.cloud.fields.size(), before.cloud.fields.size()) << "rgb kept";
  const Eigen::Matrix3Xd p = vertexPositions(before.cloud, NonFinitePolicy::Keep);
  const Eigen::Matrix3Xd q = vertexPositions(after.cloud, NonFinitePolicy::Keep);
  int moved = 0;
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    ASSERT_EQ(p.col(i).allFinite(), q.col(i).allFinite()) << "pixel " << i;
    if (!p.col(i).allFinite()) continue;
    // On the same ray from the sensor (the origin here), to float precision.
    EXPECT_LT(p.col(i).normalized().cross(q.col(i).normalized()).norm(), 1e-6) << "pixel " << i;
    moved += (p.col(i) - q.col(i)).norm() > 0.0;
  }
  EXPECT_GT(moved, p.cols() / 2);

  const ToolRun flat =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL, sharedData("clouds/rs1.pcd") + " " + path("flat.pcd"));
  EXPECT_EQ(flat.exit_code, 1);
  EXPECT_NE(flat.err.find("not organized"), std::string::npos) << flat.err;
  // Any format is read (a PLY range grid is organized); a mesh is not a grid.
  const ToolRun mesh =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL, sharedData("meshes/cow.off") + " " + path("c.pcd"));
  EXPECT_EQ(mesh.exit_code, 1);
  EXPECT_NE(mesh.err.find("not organized"), std::string::npos) << mesh.err;
  EXPECT_EQ(runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL, input + " " + path("x.pcd") + " -max_jump 0")
                .exit_code,
            2);
  const ToolRun zero =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL, input + " " + path("x.pcd") + " -max_depth_jump 0");
  EXPECT_EQ(zero.exit_code, 2);
  EXPECT_NE(zero.err.find("-max_depth_jump must be > 0"), std::string::npos) << zero.err;
  EXPECT_EQ(runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL,
                    input + " " + path("x.pcd") + " -max_jump 0.1 -max_depth_jump 0.1")
                .exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(path("flat.pcd")));
  expectNoLeftovers();
}

TEST_F(SmoothingTools, OrganizedSmoothingNeverWritesInfinitiesAndKeepsPointsAtTheSensor) {
  const std::string input = sharedData("clouds/table_scene_mug_stereo_textured.pcd");
  const ToolRun refused =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL,
              input + " " + path("a.pcd") + " -method explicit -lambda_dt 1e300");
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  const ToolRun blown =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL,
              input + " " + path("b.pcd") + " -method explicit -lambda_dt 1e300 -allow_unstable");
  EXPECT_EQ(blown.exit_code, 1) << blown.err;
  EXPECT_NE(blown.err.find("pcl_ddg_smooth_organized: error: "), std::string::npos) << blown.err;
  EXPECT_FALSE(std::filesystem::exists(path("a.pcd")));
  EXPECT_FALSE(std::filesystem::exists(path("b.pcd")));

  // A 3 x 2 frame: a point at the sensor origin, a hole, four points on a plane.
  const std::string header =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 2\n"
      "POINTS 6\nDATA ascii\n";
  writeText(path("frame.pcd"), header + "0 0 0\nnan nan nan\n1 0 2\n0 1 2.2\n1 1 1.9\n2 1 2\n");
  const ToolRun frame =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL, path("frame.pcd") + " " + path("frame_out.pcd"));
  ASSERT_EQ(frame.exit_code, 0) << frame.err;
  const Eigen::Matrix3Xd q =
      vertexPositions(loadMesh(path("frame_out.pcd")).cloud, NonFinitePolicy::Keep);
  EXPECT_EQ(q.col(0), Eigen::Vector3d::Zero()) << "the point at the sensor stays";
  EXPECT_TRUE(q.col(1).array().isNaN().all()) << "the hole stays a hole";
  EXPECT_TRUE(q.rightCols(4).allFinite());

  writeText(path("empty.pcd"), header +
                                   "nan nan nan\nnan nan nan\nnan nan nan\nnan nan nan\n"
                                   "nan nan nan\nnan nan nan\n");
  const ToolRun empty =
      runTool(PCL_DDG_SMOOTH_ORGANIZED_TOOL, path("empty.pcd") + " " + path("empty_out.pcd"));
  ASSERT_EQ(empty.exit_code, 0) << empty.err;
  EXPECT_NE(empty.err.find("no valid pixel"), std::string::npos) << empty.err;
  expectNoLeftovers();
}

TEST_F(SmoothingTools, CurvatureSmoothingReducesTheNoiseOfANoisySphere) {
  saveMesh(path("sphere.ply"), polygonMeshOf(makeIcosphere(4, 2.0, 0.15)));
  const ToolRun raw = runTool(PCL_DDG_CURVATURE_TOOL, path("sphere.ply") + " " + path("raw.ply"));
  const ToolRun smooth =
      runTool(PCL_DDG_CURVATURE_TOOL, path("sphere.ply") + " " + path("smooth.ply") + " -smooth 3");
  ASSERT_EQ(raw.exit_code, 0) << raw.err;
  ASSERT_EQ(smooth.exit_code, 0) << smooth.err;
  const auto rmsError = [](const std::string& file) {
    const Eigen::VectorXd h = vertexScalarField(loadMesh(file).cloud, "mean_curvature");
    return std::sqrt((h.array() - 0.5).square().mean());
  };
  const double raw_error = rmsError(path("raw.ply")), smooth_error = rmsError(path("smooth.ply"));
  std::printf("jittered sphere r = 2: H RMS error %.3e raw, %.3e with -smooth 3\n", raw_error,
              smooth_error);
  EXPECT_LT(smooth_error, 0.5 * raw_error);
  EXPECT_EQ(runTool(PCL_DDG_CURVATURE_TOOL,
                    sharedData("clouds/bun0.pcd") + " " + path("c.ply") + " -smooth 1")
                .exit_code,
            2);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
