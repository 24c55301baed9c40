// The tools' error promise, for every tool and every kind of bad input file: exit code 1, exactly
// one line on stderr ("pcl_ddg_x: error: ..." with no empty fields), no output file and no
// temporary left behind.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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
    {"pcl_ddg_compare_neighbourhoods", PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL, "ply", "out.ply"},
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

/** The tools' error promise: exactly one non-empty line on stderr, "tool: error: ...". */
::testing::AssertionResult isOneErrorLine(const std::string& tool_name, const std::string& err) {
  const std::vector<std::string> lines = nonEmptyLines(err);
  if (lines.size() == 1 && lines[0].rfind(tool_name + ": error: ", 0) == 0)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "not one \"" << tool_name << ": error:\" line:\n" << err;
}

/** Every name in a folder (temporaries included), sorted. */
std::vector<std::string> folderListing(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string extensionOf(const std::string& file) {
  return std::filesystem::path(file).extension().string().substr(1);
}

/** A small organized depth frame: 8 x 6 pixels of a tilted, curved surface seen from the origin. */
std::string organizedFrame() {
  std::ostringstream pcd;
  pcd << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 8\nHEIGHT 6\n"
         "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 48\nDATA ascii\n";
  pcd.precision(9);
  for (int v = 0; v < 6; ++v) {
    for (int u = 0; u < 8; ++u) {
      // On the pixel's ray: coordinates off any lattice, so no quantisation warning is printed.
      const double rx = (u - 3.5) / 20, ry = (v - 2.5) / 20, z = 2 + 0.3 * rx + 0.2 * rx * ry;
      pcd << rx * z << " " << ry * z << " " << z << "\n";
    }
  }
  return pcd.str();
}

/** Writes folder/name.<the tool's input extension>: the bunny mesh, or an organized frame. */
std::string writeInput(const Tool& tool, const std::string& folder, const std::string& name) {
  const std::string file = folder + "/" + name + "." + tool.input_extension;
  if (std::string(tool.input_extension) == "pcd")
    writeText(file, organizedFrame());
  else
    std::filesystem::copy_file(std::string(PCL_DDG_SOURCE_DIR) + "/data/bunny.ply", file);
  return file;
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
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method robust -memory 1G -orient mst"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method robust -k 2"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method pca -radius 1 -max_nn 0"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-neighbours tree"},
      {PCL_DDG_NORMALS_TOOL, "missing.ply", "-method mean_curvature -epsilon -1"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-smooth -1"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-smooth abc"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-method quadric -k abc"},
      {PCL_DDG_CURVATURE_TOOL, "missing.ply", "-area heron"},
      {PCL_DDG_COMPARE_NEIGHBOURHOODS_TOOL, "missing.ply", "-k 16 -radius 1"},
      {PCL_DDG_SMOOTH_TOOL, "missing.ply", "-lambda_dt abc"},
      {PCL_DDG_SMOOTH_TOOL, "missing.ply", "-freeze_weights -rebuild_weights"},
      {PCL_DDG_SMOOTH_TOOL, "missing.ply", "-update_mass -rebuild_weights"},
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
  // Runs with phases of a tenth of a second or more (igea's topology, rs1's quadrics).
  const std::pair<const char*, std::string> runs[] = {
      {PCL_DDG_INFO_TOOL, sharedData("meshes/igea.ply")},
      {PCL_DDG_NORMALS_TOOL,
       sharedData("clouds/rs1.pcd") + " " + path("n.pcd") + " -method quadric"},
  };
  int total_long_phases = 0;
  for (const auto& [binary, arguments] : runs) {
    SCOPED_TRACE(binary);
    // script(1) gives the tool a pseudo-terminal as its stderr.
    const ToolRun terminal = runTool("PCL_DDG_PROGRESS_AFTER_MS=0 script -qec '" +
                                         std::string(binary) + " " + arguments + "' /dev/null",
                                     "");
    ASSERT_EQ(terminal.exit_code, 0) << terminal.out << terminal.err;
    // The running time is drawn by a thread started with the phase: asserted only for phases
    // that lasted long enough for it to have run (200 ms against a delay of 0), so the test does
    // not depend on who wins a race on a fast machine.
    int long_phases = 0;
    for (std::size_t done = terminal.out.find("[done, "); done != std::string::npos;
         done = terminal.out.find("[done, ", done + 1)) {
      std::size_t at = done + 7;  // past any colour escapes ("\033[0;36m") to the number
      while (at < terminal.out.size() && terminal.out[at] == '\033')
        at = terminal.out.find('m', at) + 1;
      const double ms = std::strtod(terminal.out.c_str() + at, nullptr);
      if (ms < 200.0) continue;
      ++long_phases;
      const std::size_t line = terminal.out.rfind('\n', done);
      const std::string phase =
          terminal.out.substr(line == std::string::npos ? 0 : line, done - line);
      EXPECT_NE(phase.find(" s) "), std::string::npos) << phase;
    }
    total_long_phases += long_phases;
  }
  // Into a pipe the same run shows no running time.
  const ToolRun pipe =
      runTool(std::string("PCL_DDG_PROGRESS_AFTER_MS=0 ") + runs[0].first, runs[0].second);
  ASSERT_EQ(pipe.exit_code, 0) << pipe.err;
  EXPECT_EQ(pipe.err.find(" s) "), std::string::npos) << pipe.err;
  EXPECT_GT(total_long_phases, 0) << "no phase lasted 200 ms: the runs prove nothing";
}

// Issue 28, item 1: `pcl_ddg_normals scan.ply scan.ply` used to replace the scan (exit 0). The
// output is compared with the input by identity (device and inode), so every spelling and every
// link of the input is refused before anything is read, and the folder is left as it was.
TEST_F(ToolErrors, AnOutputThatIsTheInputIsRefusedHoweverItIsSpelled) {
  for (const Tool& tool : kTools) {
    if (!*tool.output) continue;
    SCOPED_TRACE(tool.name);
    const std::string folder = path(tool.name);
    std::filesystem::create_directories(folder + "/sub");
    const std::string input = writeInput(tool, folder, "input");
    const std::string in_name = std::filesystem::path(input).filename().string();
    // Links carry the output's extension, so render (a .png) is covered by them too.
    const std::string out_ext = extensionOf(tool.output);
    const std::string symlink = "symlink." + out_ext, hard_link = "hardlink." + out_ext;
    std::filesystem::create_symlink(in_name, folder + "/" + symlink);
    std::filesystem::create_hard_link(input, folder + "/" + hard_link);
    std::vector<std::string> outputs = {symlink, hard_link};
    if (out_ext == tool.input_extension)
      outputs.insert(outputs.end(), {in_name, "./sub/../" + in_name, input});
    const std::string bytes = readBytes(input);
    const std::vector<std::string> listing = folderListing(folder);
    for (const std::string& output : outputs) {
      SCOPED_TRACE(output);
      // Run inside the folder: the input is spelled relative, the output in other ways.
      const ToolRun run = runTool("cd " + folder + " && " + tool.binary, in_name + " " + output);
      EXPECT_EQ(run.exit_code, 2) << run.err;
      EXPECT_TRUE(isOneErrorLine(tool.name, run.err));
      EXPECT_TRUE(readBytes(input) == bytes) << "the input was changed";
      EXPECT_EQ(folderListing(folder), listing) << "a file was written";
      // A rename over a link would keep the name but replace the link.
      EXPECT_TRUE(std::filesystem::is_symlink(folder + "/" + symlink));
      EXPECT_TRUE(std::filesystem::equivalent(input, folder + "/" + hard_link));
    }
    // With a new output the same command works: the refusals are the identity check alone.
    EXPECT_EQ(runTool("cd " + folder + " && " + tool.binary, in_name + " " + tool.output).exit_code,
              0);
  }
}

// Batch mode: an output that is one of the inputs (a link from -output_dir into -input_dir) is
// refused before the first file is processed, so that nothing at all is written.
TEST_F(ToolErrors, BatchModeRefusesAnOutputThatIsAnInput) {
  for (const Tool& tool : kTools) {
    if (!*tool.output) continue;
    const std::string out_ext = extensionOf(tool.output);
    for (const std::string link_kind : {"symbolic", "hard"}) {
      SCOPED_TRACE(std::string(tool.name) + ", " + link_kind + " link");
      const std::string in = path(std::string(tool.name) + "_" + link_kind + "_in");
      const std::string out = path(std::string(tool.name) + "_" + link_kind + "_out");
      std::filesystem::create_directories(in);
      std::filesystem::create_directories(out);
      writeInput(tool, in, "a");  // processed first, were the outputs checked one by one
      const std::string input = writeInput(tool, in, "scan");
      const std::string link = out + "/scan." + out_ext;
      if (link_kind == "hard")
        std::filesystem::create_hard_link(input, link);
      else
        std::filesystem::create_symlink(input, link);
      const std::string bytes = readBytes(input);

      const ToolRun run = runTool(tool.binary, "-input_dir " + in + " -output_dir " + out);
      EXPECT_EQ(run.exit_code, 2) << run.err;
      EXPECT_TRUE(isOneErrorLine(tool.name, run.err));
      EXPECT_TRUE(readBytes(input) == bytes) << "the input was changed";
      EXPECT_EQ(folderListing(out), std::vector<std::string>{"scan." + out_ext})
          << "a file was written";
      EXPECT_TRUE(std::filesystem::equivalent(input, link)) << "the link was replaced";
    }
  }
}

// Batch mode: x.ply and x.off would both be written as x.ply, the second replacing the first.
// (The rule is forEachInput's, shared by every tool: one tool shows it.)
TEST_F(ToolErrors, BatchModeRefusesTwoInputsWritingOneOutput) {
  const std::string in = path("in"), out = path("out");
  std::filesystem::create_directories(in);
  std::filesystem::create_directories(out);
  writeInput(kTools[1], in, "x");
  writeText(in + "/x.off",
            "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
            "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, "-input_dir " + in + " -output_dir " + out);
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_TRUE(isOneErrorLine("pcl_ddg_normals", run.err));
  EXPECT_NE(run.err.find(out + "/x.ply"), std::string::npos) << run.err;
  EXPECT_TRUE(folderListing(out).empty()) << "a file was written";
}

// pcl_ddg_normals writes a second file with -normal_map: it must not be the input either.
TEST_F(ToolErrors, TheNormalMapCannotBeTheInput) {
  for (const std::string map : {"frame.pcd", "symlink.png", "hardlink.png"}) {
    SCOPED_TRACE(map);
    // A folder per case, so that each starts from an untouched frame.
    const std::string folder = path(map + "_case");
    std::filesystem::create_directories(folder);
    const std::string frame = folder + "/frame.pcd";
    writeText(frame, organizedFrame());
    std::filesystem::create_symlink(frame, folder + "/symlink.png");
    std::filesystem::create_hard_link(frame, folder + "/hardlink.png");
    const std::string bytes = readBytes(frame);
    const ToolRun run = runTool(PCL_DDG_NORMALS_TOOL, frame + " " + folder + "/out.pcd" +
                                                          " -normal_map " + folder + "/" + map);
    EXPECT_EQ(run.exit_code, 2) << run.err;
    EXPECT_TRUE(isOneErrorLine("pcl_ddg_normals", run.err));
    EXPECT_TRUE(readBytes(frame) == bytes) << "the input was changed";
    EXPECT_FALSE(std::filesystem::exists(folder + "/out.pcd"));
    EXPECT_TRUE(std::filesystem::is_symlink(folder + "/symlink.png"));
    EXPECT_TRUE(std::filesystem::equivalent(frame, folder + "/hardlink.png"));
  }
  // The frame is organized: with another name the map is written, so only the check refused it.
  writeText(path("frame.pcd"), organizedFrame());
  EXPECT_EQ(runTool(PCL_DDG_NORMALS_TOOL,
                    path("frame.pcd") + " " + path("out.pcd") + " -normal_map " + path("map.png"))
                .exit_code,
            0);
  EXPECT_TRUE(std::filesystem::exists(path("map.png")));
}

// Issue 28, item 2: a missing output folder used to be reported after the whole computation. It
// is checked first: one line naming the folder, and no progress line since nothing was loaded.
TEST_F(ToolErrors, AnOutputInAMissingFolderFailsBeforeAnyWork) {
  const std::string missing = path("missing");
  for (const Tool& tool : kTools) {
    if (!*tool.output) continue;
    SCOPED_TRACE(tool.name);
    const std::string input = writeInput(tool, dir_, tool.name);
    const ToolRun run = runTool(tool.binary, input + " " + missing + "/" + tool.output);
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_TRUE(isOneErrorLine(tool.name, run.err));
    EXPECT_NE(run.err.find("folder " + missing + " "), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("Loading"), std::string::npos) << "read before the check";
    EXPECT_EQ(run.err.find("[done"), std::string::npos) << "work done before the check";
    EXPECT_FALSE(std::filesystem::exists(missing));
  }
}

// The same for a folder that exists but cannot take the output's temporary file.
TEST_F(ToolErrors, AnOutputInAnUnwritableFolderFailsBeforeAnyWork) {
  if (geteuid() == 0) {
    GTEST_SKIP() << "running as root: root writes into a 0555 folder (access(W_OK) succeeds), so "
                    "there is nothing to refuse";
  }
  const std::string locked = path("locked");
  std::filesystem::create_directories(locked);
  std::filesystem::permissions(locked, std::filesystem::perms(0555));
  for (const Tool& tool : kTools) {
    if (!*tool.output) continue;
    SCOPED_TRACE(tool.name);
    const std::string input = writeInput(tool, dir_, tool.name);
    const ToolRun run = runTool(tool.binary, input + " " + locked + "/" + tool.output);
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_TRUE(isOneErrorLine(tool.name, run.err));
    EXPECT_NE(run.err.find("folder " + locked + " is not writable"), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("[done"), std::string::npos) << "work done before the check";
    EXPECT_TRUE(folderListing(locked).empty());
  }
  std::filesystem::permissions(locked, std::filesystem::perms(0755));  // for the next clean-up
}

// Issue 28, item 12: a usage error is one line that points to -help, not 30 lines of syntax.
TEST_F(ToolErrors, AUsageErrorIsOneLinePointingToHelp) {
  for (const Tool& tool : kTools) {
    for (const char* arguments : {"-bogus", "a.ply b.ply c.ply"}) {
      SCOPED_TRACE(std::string(tool.name) + " " + arguments);
      const ToolRun run = runTool(tool.binary, arguments);
      EXPECT_EQ(run.exit_code, 2) << run.err;
      const ::testing::AssertionResult one_line = isOneErrorLine(tool.name, run.err);
      EXPECT_TRUE(one_line);
      if (!one_line) continue;
      const std::string line = nonEmptyLines(run.err)[0];
      const std::string tail = " (see -help)";
      EXPECT_TRUE(line.size() > tail.size() &&
                  line.compare(line.size() - tail.size(), tail.size(), tail) == 0)
          << line;
      EXPECT_EQ((run.err + run.out).find("Syntax is"), std::string::npos) << run.out;
    }
    // Where the line points, the syntax is.
    const ToolRun help = runTool(tool.binary, "-help");
    EXPECT_EQ(help.exit_code, 0);
    EXPECT_NE(help.out.find(std::string("Syntax is: ") + tool.name), std::string::npos);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
