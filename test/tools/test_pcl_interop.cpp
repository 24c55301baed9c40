// What PCL code and viewers read from the tools' outputs: PCL's own readers into PCL's point
// types, colours in each format's layout (packed rgb in PCD for pcl_viewer, red green blue and
// quality in PLY for MeshLab), a cloud's own colours kept unless a colour map is asked for.
#include <gtest/gtest.h>

#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

class PCLInterop : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void run(const char* tool, const std::string& arguments, std::string* err = nullptr) const {
    const ToolRun r = runTool(tool, arguments);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    if (err) *err = r.err;
  }
  std::string dir_;
};

// A PCD of many LZF blocks (its planar bytes are compressed a MiB at a time): PCL's reader and
// ours get every value back, the incompressible random ones and the runs alike.
TEST_F(PCLInterop, ACompressedPcdOfManyBlocksLoadsInPCL) {
  const int n = 300000;  // 4.8 MB of planar floats: five blocks
  Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Random(3, n) * 100.0;
  p.rightCols(n / 3).setConstant(1.5);  // a long run LZF shortens
  MeshFile file;
  file.mesh.cloud.width = n;
  file.mesh.cloud.height = 1;
  setVertexCoordinates(file.mesh.cloud, p.cast<float>().cast<double>(), FieldPrecision::Float);
  const Eigen::VectorXd curvature = Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
  setVertexField(file.mesh.cloud, "curvature", curvature);
  saveMesh(path("many.pcd"), file.mesh);
  pcl::PointCloud<pcl::PointXYZINormal> cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(path("many.pcd"), cloud), 0);
  ASSERT_EQ(cloud.size(), static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    ASSERT_EQ(cloud[i].getVector3fMap(), p.col(i).cast<float>()) << i;
    ASSERT_EQ(cloud[i].curvature, static_cast<float>(curvature[i])) << i;
  }
  const MeshFile back = readMeshFile(path("many.pcd"));
  EXPECT_TRUE(back.positions == p.cast<float>().cast<double>());
}

// bunny.off's coordinates are decimal text that float cannot hold exactly: before PCL got float
// x y z, these came out of pcl::io::loadPCDFile as zeros.
TEST_F(PCLInterop, MeshNormalsInAPcdLoadIntoPointNormalWithPCLsCurvature) {
  const std::string bunny = sharedData("meshes/bunny.off");
  run(PCL_DDG_NORMALS_TOOL, bunny + " " + path("n.pcd") + " -method area");
  pcl::PointCloud<pcl::PointNormal> cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(path("n.pcd"), cloud), 0);
  const MeshFile input = readMeshFile(bunny);
  ASSERT_EQ(static_cast<Eigen::Index>(cloud.size()), input.positions.cols());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Index v = static_cast<Eigen::Index>(i);
    ASSERT_EQ(cloud[i].getVector3fMap(), input.positions.col(v).cast<float>()) << i;
    ASSERT_NEAR(cloud[i].getNormalVector3fMap().norm(), 1.0f, 1e-6f) << i;
    ASSERT_TRUE(cloud[i].curvature >= 0.0f && cloud[i].curvature <= 1.0f / 3.0f) << i;
  }
}

TEST_F(PCLInterop, ColoursAndNormalsLoadIntoPointXYZRGBNormal) {
  const std::string bunny = sharedData("meshes/bunny.off");
  const std::string options = " -method quadric -k 20 -color mean";
  run(PCL_DDG_CURVATURE_TOOL, bunny + " " + path("c.pcd") + options);
  run(PCL_DDG_CURVATURE_TOOL, bunny + " " + path("c.ply") + options);
  pcl::PointCloud<pcl::PointXYZRGBNormal> cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(path("c.pcd"), cloud), 0);
  // The same colours as the PLY's red green blue (what MeshLab shows).
  const pcl::PolygonMesh ply = loadMesh(path("c.ply"));
  const VertexColors colors = vertexColors(ply.cloud);
  const Eigen::VectorXd nz = vertexScalarField(ply.cloud, "nz");
  ASSERT_EQ(static_cast<Eigen::Index>(cloud.size()), colors.cols());
  int coloured = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Index v = static_cast<Eigen::Index>(i);
    ASSERT_EQ(cloud[i].r, colors(0, v)) << i;
    ASSERT_EQ(cloud[i].g, colors(1, v)) << i;
    ASSERT_EQ(cloud[i].b, colors(2, v)) << i;
    ASSERT_EQ(cloud[i].normal_z, static_cast<float>(nz[v])) << i;
    ASSERT_NEAR(cloud[i].getNormalVector3fMap().norm(), 1.0f, 1e-6f) << i;
    coloured += colors(0, v) != colors(2, v);  // red or blue, not the grey of H = 0
  }
  EXPECT_GT(coloured, static_cast<int>(cloud.size()) / 2);
  // In PLY, the coloured field is also MeshLab's quality.
  EXPECT_EQ(vertexScalarField(ply.cloud, "quality"),
            vertexScalarField(ply.cloud, "mean_curvature"));
  EXPECT_FALSE(hasVertexField(loadMesh(path("c.pcd")).cloud, "quality"));
}

TEST_F(PCLInterop, ACloudsOwnColoursAreKeptUnlessAColourMapIsAskedFor) {
  // office1.pcd: a Kinect frame with a packed rgb.
  const std::string office = sharedData("clouds/office1.pcd");
  const VertexColors own = vertexColors(loadMesh(office).cloud);
  std::string err;
  run(PCL_DDG_NORMALS_TOOL, office + " " + path("n.ply") + " -k 8", &err);
  EXPECT_EQ(vertexColors(loadMesh(path("n.ply")).cloud), own);  // as red green blue now
  EXPECT_EQ(vertexColorLayout(loadMesh(path("n.ply")).cloud), ColorLayout::Channels);
  run(PCL_DDG_NORMALS_TOOL, path("n.ply") + " " + path("n.pcd") + " -k 8");
  EXPECT_EQ(vertexColors(loadMesh(path("n.pcd")).cloud), own);  // and packed again
  EXPECT_EQ(vertexColorLayout(loadMesh(path("n.pcd")).cloud), ColorLayout::PackedRGB);
  EXPECT_EQ(err.find("colours are replaced"), std::string::npos) << err;

  run(PCL_DDG_CURVATURE_TOOL, path("n.ply") + " " + path("c.ply") + " -k 12 -color gauss", &err);
  EXPECT_NE(err.find("the input's own colours are replaced by the colour map of gauss_curvature"),
            std::string::npos)
      << err;
  EXPECT_NE(vertexColors(loadMesh(path("c.ply")).cloud), own);
}

TEST_F(PCLInterop, ComparisonColoursOnlyWhatHasNoColoursUnlessAsked) {
  pcl::PolygonMesh bunny = loadMesh(sharedData("meshes/bunny.off"));
  VertexColors green(3, bunny.cloud.width * bunny.cloud.height);
  green.colwise() = (Eigen::Matrix<std::uint8_t, 3, 1>() << 0, 200, 0).finished();
  setVertexColors(bunny.cloud, green);
  saveMesh(path("green.ply"), bunny);
  run(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL, path("green.ply") + " " + path("kept.ply"));
  const pcl::PolygonMesh kept = loadMesh(path("kept.ply"));
  EXPECT_EQ(vertexColors(kept.cloud), green);
  EXPECT_FALSE(hasVertexField(kept.cloud, "quality"));
  std::string err;
  run(PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL,
      path("green.ply") + " " + path("map.ply") + " -color overlap", &err);
  const pcl::PolygonMesh map = loadMesh(path("map.ply"));
  EXPECT_NE(vertexColors(map.cloud), green);
  EXPECT_EQ(vertexScalarField(map.cloud, "quality"), vertexScalarField(map.cloud, "overlap"));
  EXPECT_NE(err.find("colours are replaced"), std::string::npos) << err;
}

TEST_F(PCLInterop, DoublePrecisionInAPcdIsWarnedAboutAndDoublesInTheInputStayDouble) {
  const std::string bunny = sharedData("meshes/bunny.off");
  std::string err;
  run(PCL_DDG_NORMALS_TOOL, bunny + " " + path("d.pcd") + " -precision double", &err);
  EXPECT_NE(err.find("cannot read into PCL's float point types"), std::string::npos) << err;
  EXPECT_EQ(readMeshFile(path("d.pcd")).positions, readMeshFile(bunny).positions);  // exact
  run(PCL_DDG_NORMALS_TOOL, bunny + " " + path("f.pcd"), &err);
  EXPECT_EQ(err.find("double"), std::string::npos) << err;
  // A file that declares double coordinates keeps them through a tool, without being asked.
  run(PCL_DDG_NORMALS_TOOL, path("d.pcd") + " " + path("dd.ply") + " -method pca", &err);
  const MeshFile twice = readMeshFile(path("dd.ply"));
  EXPECT_EQ(twice.coordinate_precision, FieldPrecision::Double);
  EXPECT_EQ(twice.positions, readMeshFile(bunny).positions);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
