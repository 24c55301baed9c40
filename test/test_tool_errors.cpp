// The tools' error promise, for every tool and every kind of bad input file: exit code 1, exactly
// one line on stderr ("pcl_ddg_x: error: ..." with no empty fields), no output file and no
// temporary left behind.
#include <gtest/gtest.h>

#include <algorithm>
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

// PCL's batch mode: every file of a folder, one broken file not stopping the others, a summary,
// exit 1 when something failed.
TEST_F(ToolErrors, BatchModeGoesOnPastABrokenFileAndSaysSo) {
  struct Batch {
    const Tool& tool;
    std::vector<std::string> good;  // shared files this tool can process
    const char* output_extension;   // "" when the tool writes no file
  };
  const Batch batches[] = {
      {kTools[0], {"meshes/cow.off", "clouds/milk.pcd"}, ""},
      {kTools[1], {"meshes/cow.off", "clouds/milk.pcd"}, "ply"},
      {kTools[2], {"meshes/cow.off", "meshes/bun_zipper_res4.ply"}, "ply"},
      {kTools[3], {"meshes/cow.off", "meshes/bun_zipper_res4.ply"}, "ply"},
      {kTools[4], {"meshes/cow.off", "meshes/bun_zipper_res4.ply"}, "png"},
      {kTools[5], {"meshes/cow.off", "meshes/bun_zipper_res4.ply"}, "ply"},
      // A PLY range grid is an organized cloud too.
      {kTools[6], {"range/bun000.ply"}, "ply"},
  };
  for (const Batch& batch : batches) {
    SCOPED_TRACE(batch.tool.name);
    const std::string in = path(std::string(batch.tool.name) + "_in");
    const std::string out = path(std::string(batch.tool.name) + "_out");
    std::filesystem::create_directories(in);
    for (const std::string& file : batch.good)
      std::filesystem::copy_file(sharedData(file),
                                 in + "/" + std::filesystem::path(file).filename().string());
    writeText(in + "/broken.off", "OFF\n3 1 0\n0 0 0\n");
    writeText(in + "/notes.txt", "not a mesh: skipped");
    const std::string dirs =
        " -input_dir " + in + (*batch.output_extension ? " -output_dir " + out : "");
    const ToolRun run = runTool(batch.tool.binary, dirs);
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find(std::string(batch.tool.name) + ": error: " + in + "/broken.off: "),
              std::string::npos)
        << run.err;
    const std::string summary = std::string(batch.tool.name) + ": " +
                                std::to_string(batch.good.size() + 1) + " files, " +
                                std::to_string(batch.good.size()) + " done, 1 failed: broken.off";
    EXPECT_NE(run.err.find(summary), std::string::npos) << run.err;
    if (*batch.output_extension) {
      std::vector<std::string> written;
      for (const auto& entry : std::filesystem::directory_iterator(out))
        written.push_back(entry.path().filename().string());
      std::sort(written.begin(), written.end());
      std::vector<std::string> expected;
      for (const std::string& file : batch.good) {
        const std::filesystem::path name = std::filesystem::path(file).filename();
        const std::string ext = name.extension().string().substr(1);
        // Kept when the tool writes that format, else the tool's first output format.
        const bool png = std::string(batch.output_extension) == "png";
        expected.push_back(name.stem().string() + "." +
                           (png                            ? "png"
                            : ext == "ply" || ext == "pcd" ? ext
                                                           : "ply"));
      }
      std::sort(expected.begin(), expected.end());
      EXPECT_EQ(written, expected);
    }
    // All good: exit 0.
    std::filesystem::remove(in + "/broken.off");
    EXPECT_EQ(runTool(batch.tool.binary, dirs).exit_code, 0);
  }
}

TEST_F(ToolErrors, BatchModeOptionsAreCheckedFirst) {
  std::filesystem::create_directories(path("in"));
  const std::string normals = PCL_DDG_NORMALS_TOOL;
  for (const std::string& arguments :
       {" -input_dir " + path("in"), " -output_dir " + path("out") + " in.ply out.ply",
        " -input_dir " + path("in") + " -output_dir " + path("in"),
        " -input_dir " + path("in") + " -output_dir " + path("out") + " extra.ply",
        " -input_dir " + path("missing") + " -output_dir " + path("out")}) {
    const ToolRun run = runTool(normals, arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.err;
  }
  EXPECT_EQ(runTool(PCL_DDG_INFO_TOOL, " -input_dir " + path("in") + " -output_dir " + path("o"))
                .exit_code,
            2);
  // An empty folder is a failure, not a silent success.
  EXPECT_EQ(runTool(normals, " -input_dir " + path("in") + " -output_dir " + path("out")).exit_code,
            1);
}

// On a terminal a long phase shows its running time; logs and pipes get the timing line alone.
// (The delay is set to 0 here so that short runs count as long.)
TEST_F(ToolErrors, LongPhasesShowTheirRunningTimeOnATerminal) {
  // Each run has a phase of a tenth of a second or more, so that the running time, drawn by a
  // thread started with the phase, has long enough to appear.
  const std::string igea = sharedData("meshes/igea.ply");
  const std::pair<const char*, std::string> runs[] = {
      {PCL_DDG_INFO_TOOL, igea},
      {PCL_DDG_NORMALS_TOOL,
       sharedData("clouds/rs1.pcd") + " " + path("n.pcd") + " -method quadric"},
      {PCL_DDG_SMOOTH_TOOL, igea + " " + path("s.ply")},
  };
  for (const auto& [binary, arguments] : runs) {
    SCOPED_TRACE(binary);
    // script(1) gives the tool a pseudo-terminal as its stderr.
    const ToolRun terminal = runTool("PCL_DDG_PROGRESS_AFTER_MS=0 script -qec '" +
                                         std::string(binary) + " " + arguments + "' /dev/null",
                                     "");
    ASSERT_EQ(terminal.exit_code, 0) << terminal.out << terminal.err;
    EXPECT_NE(terminal.out.find(" s) "), std::string::npos) << terminal.out;
    EXPECT_NE(terminal.out.find("[done, "), std::string::npos) << terminal.out;
    const ToolRun pipe = runTool(std::string("PCL_DDG_PROGRESS_AFTER_MS=0 ") + binary, arguments);
    ASSERT_EQ(pipe.exit_code, 0) << pipe.err;
    EXPECT_EQ(pipe.err.find(" s) "), std::string::npos) << pipe.err;
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
