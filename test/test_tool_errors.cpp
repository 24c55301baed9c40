// The tools' error promise, for every tool and every kind of bad input file: exit code 1, exactly
// one line on stderr ("pcl_ddg_x: error: ..." with no empty fields), no output file and no
// temporary left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <vector>

#include "pcl_ddg/version.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

struct Tool {
  const char* name;
  const char* binary;
  const char* input_extension;
  const char* output;
};

const Tool kTools[] = {
    {"pcl_ddg_info", PCL_DDG_INFO_TOOL, "ply", ""},
    {"pcl_ddg_normals", PCL_DDG_NORMALS_TOOL, "ply", "out.ply"},
    {"pcl_ddg_curvature", PCL_DDG_CURVATURE_TOOL, "ply", "out.ply"},
    {"pcl_ddg_compare_neighbourhoods", PCL_DDG_COMPARE_TOOL, "ply", "out.ply"},
    {"pcl_ddg_render", PCL_DDG_RENDER_TOOL, "ply", "out.png"},
    {"pcl_ddg_smooth", PCL_DDG_SMOOTH_TOOL, "ply", "out.ply"},
    {"pcl_ddg_smooth_organized", PCL_DDG_SMOOTH_ORGANIZED_TOOL, "pcd", "out.pcd"},
};

std::vector<std::string> nonEmptyLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find_first_not_of(" \r\t") != std::string::npos) lines.push_back(line);
  }
  return lines;
}

class ToolErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

TEST_F(ToolErrors, EveryToolGivesOneErrorLineForEveryBadFile) {
  // Bad inputs by kind, each written with the extension the tool expects.
  const std::vector<std::pair<std::string, std::string>> ply_inputs = {
      {"truncated", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n"},
      {"garbage", std::string("\x01\x02\xff garbage\n", 12)},
      {"empty", ""},
      {"lying",
       "ply\nformat binary_little_endian 1.0\nelement vertex 357913942\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n"},
      {"outofrange",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty uchar x\nproperty uchar "
       "y\nproperty uchar z\nend_header\n300 0 0\n"}};
  const std::vector<std::pair<std::string, std::string>> pcd_inputs = {
      {"truncated",
       "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\n"
       "POINTS 4\nDATA binary\n1234"},
      {"garbage", std::string("\x01\x02\xff garbage\n", 12)},
      {"empty", ""},
      {"count",
       "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 -1\nWIDTH 1\n"
       "HEIGHT 1\nPOINTS 1\nDATA ascii\n0 0 0\n"}};
  std::filesystem::create_directory(path("folder.ply"));
  std::filesystem::create_directory(path("folder.pcd"));
  std::filesystem::create_symlink("/dev/zero", path("zero.ply"));
  std::filesystem::create_symlink("/dev/zero", path("zero.pcd"));

  for (const Tool& tool : kTools) {
    const bool pcd = std::string(tool.input_extension) == "pcd";
    std::vector<std::string> inputs = {path(std::string("missing.") + tool.input_extension),
                                       path(std::string("folder.") + tool.input_extension),
                                       path(std::string("zero.") + tool.input_extension)};
    for (const auto& [name, content] : pcd ? pcd_inputs : ply_inputs) {
      inputs.push_back(path(name + "." + tool.input_extension));
      writeText(inputs.back(), content);
    }
    for (const std::string& input : inputs) {
      SCOPED_TRACE(std::string(tool.name) + " " + input);
      const std::string output = *tool.output ? path(tool.output) : "";
      const ToolRun run = runTool(tool.binary, input + " " + output);
      EXPECT_EQ(run.exit_code, 1);
      const std::vector<std::string> lines = nonEmptyLines(run.err);
      ASSERT_EQ(lines.size(), 1u) << run.err;
      const std::string prefix = std::string(tool.name) + ": error: ";
      EXPECT_EQ(lines[0].rfind(prefix, 0), 0u) << lines[0];
      EXPECT_EQ(lines[0].find(": :"), std::string::npos) << lines[0];
      EXPECT_GT(lines[0].size(), prefix.size() + input.size() + 4) << "a reason is given";
      if (*tool.output) EXPECT_FALSE(std::filesystem::exists(output));
    }
  }
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

TEST_F(ToolErrors, BadOptionsFailBeforeAnyFileIsRead) {
  // The input does not exist: a usage error (exit 2) rather than "no such file" (exit 1) proves
  // that the option was checked before the input was opened.
  struct Case {
    const char* binary;
    const char* input;
    const char* options;
  };
  const Case cases[] = {
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method pca -k abc"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method pca -k 2"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method pca -k 16 -radius 0.1"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method pca -max_nn 8"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method pca -radius 2.5x"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method pca -radius 1 -max_nn 0"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-neighbours tree"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method mean_curvature -epsilon -1"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-smooth -1"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-smooth abc"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-method quadric -k abc"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-area heron"},
      {PCL_DDG_COMPARE_TOOL, "missing.ply", "-k 16 -radius 1"},
      {PCL_DDG_SMOOTH_TOOL, "missing.ply", "-lambda_dt abc"},
      {PCL_DDG_SMOOTH_TOOL, "missing.ply", "-freeze_weights -rebuild_weights"},
      {PCL_DDG_SMOOTH_ORGANIZED_TOOL, "missing.pcd", "-method explicit -lambda_dt 1"},
      {PCL_DDG_SMOOTH_ORGANIZED_TOOL, "missing.pcd", "-iterations 0"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.binary) + " " + c.options);
    const ToolRun run = runTool(c.binary, path(c.input) + " " + path("out.ply") + " " + c.options);
    EXPECT_EQ(run.exit_code, 2) << run.err;
    EXPECT_NE(run.err.find(": error: "), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("No such file"), std::string::npos) << run.err;
  }
}

TEST_F(ToolErrors, KLargerThanTheCloudIsRefused) {
  writeText(path("three.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL,
                              path("three.obj") + " " + path("out.ply") + " -method pca -k 5");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("-k 5 is more than the 3 points of the input"), std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
}

TEST_F(ToolErrors, EveryToolSaysItsVersion) {
  for (const Tool& tool : kTools) {
    for (const char* option : {"--version", "-version"}) {
      const ToolRun run = runTool(tool.binary, option);
      EXPECT_EQ(run.exit_code, 0) << tool.name;
      EXPECT_EQ(run.out, std::string(tool.name) + " " + PCL_DDG_VERSION_STRING + "\n");
    }
  }
}

TEST_F(ToolErrors, AFileWithoutExtensionOrOfAnUnknownKindIsNamedAsSuch) {
  writeText(path("noextension"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  writeText(path("mesh.xyz"), "0 0 0\n");
  const ToolRun none = runTool(PCL_DDG_INFO_TOOL, path("noextension"));
  EXPECT_NE(none.err.find("no file extension"), std::string::npos) << none.err;
  const ToolRun unknown = runTool(PCL_DDG_INFO_TOOL, path("mesh.xyz"));
  EXPECT_NE(unknown.err.find("unknown file type '.xyz'"), std::string::npos) << unknown.err;
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
