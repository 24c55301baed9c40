// pcl_ddg_info -json on every shared mesh against the catalogue, exit codes and error lines.
#include <gtest/gtest.h>

#include <array>
#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <cstdio>
#include <sstream>

#include "data_catalogue.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

ToolRun runInfo(const std::string& arguments) {
  return runTool(PCL_DDG_INFO_TOOL, arguments);
}

boost::property_tree::ptree json(const std::string& file) {
  const ToolRun run = runInfo(file + " -json");
  EXPECT_EQ(run.exit_code, 0) << file << ": " << run.err;
  std::istringstream in(run.out);
  boost::property_tree::ptree tree;
  boost::property_tree::read_json(in, tree);
  return tree;
}

TEST(PclDdgInfo, JsonMatchesTheCatalogOnEverySharedMesh) {
  for (const SharedMesh& row : sharedMeshes()) {
    SCOPED_TRACE(row.path);
    const auto j = json(sharedData(row.path));
    EXPECT_EQ(j.get<int>("vertices"), row.vertices);
    EXPECT_EQ(j.get<int>("faces"), row.faces);
    EXPECT_EQ(j.get<int>("boundary_edges"), row.boundary_edges);
    EXPECT_EQ(j.get<int>("nonmanifold_edges"), row.nonmanifold_edges);
    EXPECT_EQ(j.get<int>("duplicate_faces"), row.duplicate_faces);
    EXPECT_EQ(j.get<int>("unreferenced_vertices"), row.unreferenced_vertices);
    EXPECT_EQ(j.get<int>("out_of_range_faces"), 0);
    EXPECT_GT(j.get<double>("mean_edge_length"), 0.0);
    if (row.boundary_edges == 0 && row.nonmanifold_edges == 0) {
      // Closed scans: chi = 2 - 2g, and the catalogue names rocker-arm as the genus-1 model.
      const int genus = std::string(row.path) == "meshes/rocker-arm.off" ? 1 : 0;
      EXPECT_EQ(j.get<int>("genus"), genus);
      EXPECT_EQ(j.get<int>("euler_characteristic"), 2 - 2 * genus);
    }
  }
}

TEST(PclDdgInfo, ReportsCloudLayout) {
  const auto office = json(sharedData("clouds/office1.pcd"));
  EXPECT_EQ(office.get<int>("width"), 640);
  EXPECT_EQ(office.get<int>("height"), 480);
  EXPECT_GT(office.get<int>("nan_points"), 0);
  const auto room = json(sharedData("clouds/tutorials_room_scan1.pcd"));
  // "about half the points are exact duplicates"
  EXPECT_NEAR(room.get<double>("duplicate_points") / room.get<double>("points"), 0.5, 0.05);
}

TEST(PclDdgInfo, CountsDefectsInsteadOfRefusing) {
  const std::string dir = scratchFolder("info_defects");
  writeText(dir + "/dirty.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\nf 1 2 9\nf 1 1 2\n");
  const auto j = json(dir + "/dirty.obj");
  EXPECT_EQ(j.get<int>("out_of_range_faces"), 1);
  EXPECT_EQ(j.get<int>("degenerate_faces"), 1);
  EXPECT_EQ(j.get<int>("nonfinite_vertices"), 1);
}

TEST(PclDdgInfo, ExitCodesAndOneLineErrors) {
  EXPECT_EQ(runInfo("-h").exit_code, 0);
  const ToolRun usage = runInfo("");
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_EQ(usage.err.rfind("pcl_ddg_info: error: ", 0), 0u) << usage.err;
  EXPECT_EQ(runInfo(sharedData("meshes/cow.off") + " -bogus").exit_code, 2);
  const std::string dir = scratchFolder("info_errors");
  writeText(dir + "/broken.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n");
  const ToolRun broken = runInfo(dir + "/broken.ply");
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_NE(broken.err.find("pcl_ddg_info: error: "), std::string::npos) << broken.err;
  EXPECT_NE(broken.err.find("end_header"), std::string::npos) << broken.err;
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
