// The tools on LAS files: the same normals as from the same points in a PCD F 8 file, every field
// and VLR kept, -classes, batch mode, pcl_ddg_info's LAS report, a file of no points, and LAZ
// read and written.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "data_catalogue.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

const char* const kSurvey = "las/autzen_trim.las";

// The points of a LAS file (all, or those of one class) as a PCD with F 8 coordinates only.
void writeDoublePcd(const std::string& path, const MeshFile& las, int only_class = -1) {
  const Eigen::VectorXd classes = vertexScalarField(las.mesh.cloud, "classification");
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < las.positions.cols(); ++i)
    if (only_class < 0 || classes[i] == only_class) kept.push_back(i);
  Eigen::Matrix3Xd p(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t k = 0; k < kept.size(); ++k) p.col(k) = las.positions.col(kept[k]);
  pcl::PolygonMesh mesh = makeMesh(p, {});
  setVertexCoordinates(mesh.cloud, p, FieldPrecision::Double);
  saveMesh(path, mesh);
}

Eigen::Matrix3Xd normalsOf(const MeshFile& file) {
  Eigen::Matrix3Xd n(3, file.positions.cols());
  n.row(0) = vertexScalarField(file.mesh.cloud, "normal_x").transpose();
  n.row(1) = vertexScalarField(file.mesh.cloud, "normal_y").transpose();
  n.row(2) = vertexScalarField(file.mesh.cloud, "normal_z").transpose();
  return n;
}

bool sameValues(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  if (a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    const double x = a.data()[i], y = b.data()[i];
    if (!(x == y || (std::isnan(x) && std::isnan(y)))) return false;
  }
  return true;
}

TEST(LasTools, NormalsFromLasEqualThoseFromTheSamePointsInADoublePcd) {
  const std::string folder = scratchFolder("las_tools_pcd");
  const MeshFile las = readMeshFile(sharedData(kSurvey));
  writeDoublePcd(folder + "/same.pcd", las);
  const std::string options = " -method pca -k 12 -orient up";
  ASSERT_EQ(runTool(PCL_DDG_NORMALS_TOOL, sharedData(kSurvey) + " " + folder + "/a.las" + options)
                .exit_code,
            0);
  ASSERT_EQ(
      runTool(PCL_DDG_NORMALS_TOOL, folder + "/same.pcd " + folder + "/b.pcd" + options).exit_code,
      0);
  const MeshFile a = readMeshFile(folder + "/a.las");
  const MeshFile b = readMeshFile(folder + "/b.pcd");
  EXPECT_TRUE(sameValues(normalsOf(a), normalsOf(b)));
  EXPECT_EQ(vertexScalarField(a.mesh.cloud, "curvature"),
            vertexScalarField(b.mesh.cloud, "curvature"));
  // Every input field and VLR kept; the points' records as they were, normals after them.
  EXPECT_EQ(a.positions, las.positions);
  const std::string in = readBytes(sharedData(kSurvey)), out = readBytes(folder + "/a.las");
  const auto u32 = [](const std::string& s, std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, s.data() + at, 4);
    return v;
  };
  EXPECT_EQ(out.substr(227, u32(in, 96) - 227), in.substr(227, u32(in, 96) - 227))
      << "the projection VLRs come first, as they were";
  for (std::size_t i = 0; i < 110000; i += 997) {
    ASSERT_EQ(out.substr(u32(out, 96) + i * 50, 34), in.substr(u32(in, 96) + i * 34, 34));
  }
}

TEST(LasTools, ClassesFitsOnlyThoseClassesAndWritesEveryPoint) {
  const std::string folder = scratchFolder("las_tools_classes");
  const MeshFile las = readMeshFile(sharedData(kSurvey));
  const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, sharedData(kSurvey) + " " + folder +
                                                        "/g.las -method pca -k 10 -orient up "
                                                        "-classes 2");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("fitting 26107 of 110000 points"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("without an estimate"), std::string::npos) << run.err;
  // The ground alone, as a cloud of its own.
  writeDoublePcd(folder + "/ground.pcd", las, 2);
  ASSERT_EQ(runTool(PCL_DDG_NORMALS_TOOL,
                    folder + "/ground.pcd " + folder + "/ground_n.pcd -method pca -k 10 -orient up")
                .exit_code,
            0);
  const MeshFile out = readMeshFile(folder + "/g.las");
  ASSERT_EQ(out.positions.cols(), 110000);
  EXPECT_TRUE(out.positions == las.positions);  // the points left out keep their coordinates
  const Eigen::Matrix3Xd n = normalsOf(out);
  const Eigen::Matrix3Xd ground = normalsOf(readMeshFile(folder + "/ground_n.pcd"));
  const Eigen::VectorXd classes = vertexScalarField(out.mesh.cloud, "classification");
  Eigen::Index g = 0;
  for (Eigen::Index i = 0; i < n.cols(); ++i) {
    if (classes[i] == 2) {
      ASSERT_TRUE(sameValues(n.col(i), ground.col(g))) << "point " << i;
      ++g;
    } else {
      ASSERT_TRUE(std::isnan(n(0, i)) && std::isnan(n(1, i)) && std::isnan(n(2, i)))
          << "point " << i;
    }
  }
  EXPECT_EQ(g, ground.cols());
}

TEST(LasTools, ClassesArgumentErrors) {
  const std::string folder = scratchFolder("las_tools_class_errors");
  const std::string in = sharedData(kSurvey) + " " + folder + "/o.las -method pca";
  EXPECT_EQ(runTool(PCL_DDG_NORMALS_TOOL, in + " -classes 2,x").exit_code, 2);
  EXPECT_EQ(runTool(PCL_DDG_NORMALS_TOOL, in + " -classes 256").exit_code, 2);
  const ToolRun none = runTool(PCL_DDG_NORMALS_TOOL, in + " -classes 17");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find("no point is of the classes"), std::string::npos) << none.err;
  const ToolRun cloud = runTool(PCL_DDG_NORMALS_TOOL, sharedData("clouds/bun0.pcd") + " " + folder +
                                                          "/b.pcd -method pca -classes 2");
  EXPECT_EQ(cloud.exit_code, 1);
  EXPECT_NE(cloud.err.find("classification"), std::string::npos) << cloud.err;
  EXPECT_FALSE(std::filesystem::exists(folder + "/o.las"));
  const ToolRun quadric = runTool(
      PCL_DDG_CURVATURE_TOOL, sharedData(kSurvey) + " " + folder + "/q.las -radius 5 -classes 2,6");
  ASSERT_EQ(quadric.exit_code, 0) << quadric.err;
  // Two classes at once: the points of either are fitted (counted here from the input; this
  // trimmed survey has no class 6, so they are the ground's 26107), every point is written where it
  // was, the others have NaN curvatures, and so do the fitted points the run reports as without
  // an estimate or with NaN curvatures.
  const MeshFile las = readMeshFile(sharedData(kSurvey));
  const Eigen::VectorXd classes = vertexScalarField(las.mesh.cloud, "classification");
  const long selected = (classes.array() == 2.0 || classes.array() == 6.0).count();
  EXPECT_EQ(selected, 26107);
  EXPECT_NE(quadric.err.find("fitting " + std::to_string(selected) + " of 110000 points"),
            std::string::npos)
      << quadric.err;
  const auto reported = [&](const std::string& what) {
    const std::size_t at = quadric.err.find(what);
    if (at == std::string::npos) return 0L;
    const std::size_t start = quadric.err.rfind("warning: ", at) + std::strlen("warning: ");
    return std::stol(quadric.err.substr(start, at - start));
  };
  const long without = reported(" points without an estimate");
  const long no_curvature = reported(" points with too few neighbours or an ill-conditioned");
  const MeshFile q = readMeshFile(folder + "/q.las");
  ASSERT_EQ(q.positions, las.positions);
  const Eigen::VectorXd mean = vertexScalarField(q.mesh.cloud, "mean_curvature");
  long finite_elsewhere = 0, finite_selected = 0;
  for (Eigen::Index i = 0; i < mean.size(); ++i) {
    const bool chosen = classes[i] == 2.0 || classes[i] == 6.0;
    (chosen ? finite_selected : finite_elsewhere) += std::isfinite(mean[i]);
  }
  EXPECT_EQ(finite_elsewhere, 0);
  EXPECT_EQ(finite_selected, selected - without - no_curvature) << quadric.err;
  EXPECT_GT(finite_selected, selected / 2);
}

TEST(LasTools, BatchModeReadsAndWritesLas) {
  const std::string folder = scratchFolder("las_tools_batch");
  std::filesystem::create_directories(folder + "/in");
  std::filesystem::copy_file(sharedData("las/test1_4.las"), folder + "/in/a.las");
  std::filesystem::copy_file(sharedData("las/simple.laz"), folder + "/in/b.laz");
  const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, "-input_dir " + folder + "/in -output_dir " +
                                                        folder + "/out -method pca -k 8");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // The batch takes .las and .laz files, each written in its own format.
  EXPECT_NE(run.err.find("pcl_ddg_normals: 2 files, 2 done, 0 failed\n"), std::string::npos)
      << run.err;
  std::vector<std::string> written;
  for (const auto& entry : std::filesystem::directory_iterator(folder + "/out"))
    written.push_back(entry.path().filename().string());
  std::sort(written.begin(), written.end());
  EXPECT_EQ(written, (std::vector<std::string>{"a.las", "b.laz"}));
  const MeshFile out = readMeshFile(folder + "/out/a.las");
  EXPECT_EQ(out.las->version_minor, 4);
  EXPECT_EQ(out.las->point_format, 6);
  EXPECT_EQ(out.positions, readMeshFile(sharedData("las/test1_4.las")).positions);
  EXPECT_TRUE(hasVertexField(out.mesh.cloud, "normal_x"));
}

TEST(LasTools, InfoReportsTheLasLayout) {
  const ToolRun run = runTool(PCL_DDG_INFO_TOOL, sharedData(kSurvey));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("LAS:               1.2, point format 3"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("scale:             0.01 0.01 0.01"), std::string::npos);
  EXPECT_NE(run.out.find("LASF_Projection 34735"), std::string::npos);
  EXPECT_NE(run.out.find("class   2:         26107 (ground)"), std::string::npos) << run.out;
  const ToolRun json = runTool(PCL_DDG_INFO_TOOL, sharedData("las/extrabytes.las") + " -json");
  ASSERT_EQ(json.exit_code, 0);
  EXPECT_NE(json.out.find("\"point_format\": 3"), std::string::npos) << json.out;
  EXPECT_NE(json.out.find("\"Colors\""), std::string::npos) << json.out;
  EXPECT_EQ(std::count(json.out.begin(), json.out.end(), '\n'), 1) << "one JSON object";
}

template <typename T>
T at(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

boost::property_tree::ptree infoJson(const std::string& path) {
  const ToolRun run = runTool(PCL_DDG_INFO_TOOL, path + " -json");
  EXPECT_EQ(run.exit_code, 0) << path << ": " << run.err;
  std::istringstream in(run.out);
  boost::property_tree::ptree tree;
  boost::property_tree::read_json(in, tree);
  return tree;
}

Eigen::Vector3d vector3(const boost::property_tree::ptree& array) {
  Eigen::Vector3d v;
  int d = 0;
  for (const auto& item : array) v[d++] = item.second.get_value<double>();
  EXPECT_EQ(d, 3);
  return v;
}

// The box of the records' X * scale + offset and the header's bounds, read from the file's bytes
// at the specification's offsets (LAS 1.4 R15, table 3): pcl_ddg_info reports both, and says the
// two agree exactly when no bound differs from the records' by more than half a scale step.
TEST(LasTools, InfoComparesTheHeaderBoundsWithTheRecords) {
  for (const SharedCloud& entry : sharedLasFiles()) {
    SCOPED_TRACE(entry.path);
    const std::string path = sharedData(entry.path);
    const std::string b = readBytes(path);
    const std::uint32_t offset = at<std::uint32_t>(b, 96);
    const std::uint16_t length = at<std::uint16_t>(b, 105);
    const std::uint64_t count = b[25] >= 4 ? at<std::uint64_t>(b, 247) : at<std::uint32_t>(b, 107);
    Eigen::Vector3d scale, shift, header_min, header_max;
    for (int d = 0; d < 3; ++d) {
      scale[d] = at<double>(b, 131 + 8 * d);
      shift[d] = at<double>(b, 155 + 8 * d);
      header_max[d] = at<double>(b, 179 + 16 * d);
      header_min[d] = at<double>(b, 187 + 16 * d);
    }
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (std::uint64_t i = 0; i < count; ++i) {
      for (int d = 0; d < 3; ++d) {
        const double v = at<std::int32_t>(b, offset + i * length + 4 * d) * scale[d] + shift[d];
        lo[d] = std::min(lo[d], v);
        hi[d] = std::max(hi[d], v);
      }
    }
    bool agree = true;
    for (int d = 0; d < 3; ++d) {
      agree = agree && std::abs(header_min[d] - lo[d]) <= scale[d] / 2 &&
              std::abs(header_max[d] - hi[d]) <= scale[d] / 2;
    }
    const auto j = infoJson(path);
    EXPECT_EQ(vector3(j.get_child("bounding_box_min")), lo);
    EXPECT_EQ(vector3(j.get_child("bounding_box_max")), hi);
    EXPECT_EQ(vector3(j.get_child("las.scale")), scale);
    EXPECT_EQ(vector3(j.get_child("las.offset")), shift);
    EXPECT_EQ(vector3(j.get_child("las.header_bounds_min")), header_min);
    EXPECT_EQ(vector3(j.get_child("las.header_bounds_max")), header_max);
    EXPECT_EQ(j.get<std::string>("las.header_bounds_agree"), agree ? "true" : "false");
  }
}

// no-points.las (PDAL's): a valid LAS 1.2 file whose header counts no point.
TEST(LasTools, AFileOfNoPointsIsReportedButNotFitted) {
  const std::string path = sharedData("las/no-points.las");
  const std::string b = readBytes(path);
  const ToolRun info = runTool(PCL_DDG_INFO_TOOL, path);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("points:            0\n"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("LAS:               1.2, point format 3"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("header vs records: no records to compare"), std::string::npos);
  EXPECT_NE(info.out.find("VLR:               LASF_Projection 34735"), std::string::npos);
  const auto j = infoJson(path);
  EXPECT_EQ(j.get<int>("points"), 0);
  Eigen::Vector3d scale, shift;
  for (int d = 0; d < 3; ++d) {
    scale[d] = at<double>(b, 131 + 8 * d);
    shift[d] = at<double>(b, 155 + 8 * d);
  }
  EXPECT_EQ(vector3(j.get_child("las.scale")), scale);
  EXPECT_EQ(vector3(j.get_child("las.offset")), shift);
  EXPECT_EQ(j.get<std::string>("las.header_bounds_agree"), "null");
  EXPECT_EQ(j.get_child("las.vlrs").size(), at<std::uint32_t>(b, 100));

  const std::string folder = scratchFolder("las_tools_no_points");
  for (const char* tool : {PCL_DDG_NORMALS_TOOL, PCL_DDG_CURVATURE_TOOL}) {
    SCOPED_TRACE(tool);
    const ToolRun run = runTool(tool, path + " " + folder + "/out.las");
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    const std::string name = std::filesystem::path(tool).filename().string();
    EXPECT_NE(run.err.find(name + ": error: "), std::string::npos) << run.err;
    EXPECT_NE(run.err.find(path), std::string::npos) << run.err;
    EXPECT_NE(run.err.find("no points"), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(folder + "/out.las"));
  }
}

// LAZ in, LAZ out: pcl_ddg_info reports the decompressed layout; pcl_ddg_normals writes .laz
// whose points and fields are those of its .las output (the same run to .las), and reads back.
TEST(LasTools, LazIsReadAndWritten) {
  const std::string folder = scratchFolder("las_tools_laz");
  const ToolRun info = runTool(PCL_DDG_INFO_TOOL, sharedData("las/laz/autzen_trim.laz"));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("points:            110000"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("point format 3"), std::string::npos) << info.out;
  const std::string input = sharedData("las/laz/autzen_trim.laz");
  for (const char* output : {"/out.las", "/out.laz"}) {
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, input + " " + folder + output + " -k 8");
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  const MeshFile las = readMeshFile(folder + "/out.las"), laz = readMeshFile(folder + "/out.laz");
  EXPECT_TRUE(laz.positions == las.positions);
  EXPECT_TRUE(laz.mesh.cloud.data == las.mesh.cloud.data);
  EXPECT_TRUE(hasVertexField(laz.mesh.cloud, "normal_x"));
  EXPECT_LT(std::filesystem::file_size(folder + "/out.laz"),
            std::filesystem::file_size(folder + "/out.las") / 2);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
