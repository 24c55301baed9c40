// Clouds larger than memory: pcl_ddg_normals (and pcl_ddg_curvature) -memory reads the file a piece
// at a time, fits it tile by tile, and writes exactly what the in-memory run writes, within its
// memory budget.
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class OutOfCore : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  // The tool in memory and out of core on the same input: the outputs must be the same bytes.
  void expectSameOutput(const std::string& input, const std::string& options,
                        const std::string& memory, const char* tool = PCL_DDG_NORMALS_TOOL,
                        const std::string& ext = "ply") {
    SCOPED_TRACE(input + options + " -> ." + ext);
    // Out of core is the kd-tree's path; in memory an organized cloud would take the grid.
    const ToolRun whole =
        runTool(tool, input + " " + path("whole." + ext) + " " + options + " -neighbours kdtree");
    ASSERT_EQ(whole.exit_code, 0) << whole.err;
    const ToolRun tiled =
        runTool(tool, input + " " + path("tiled." + ext) + " " + options + " -memory " + memory);
    ASSERT_EQ(tiled.exit_code, 0) << tiled.err;
    EXPECT_NE(tiled.err.find("out of core"), std::string::npos) << tiled.err;
    EXPECT_TRUE(fileBytes(path("whole." + ext)) == fileBytes(path("tiled." + ext)))
        << "out of core differs from in memory\n"
        << tiled.err;
  }
  void expectNoScratchLeft() const {
    for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      EXPECT_EQ(name.find(".pcl_ddg_tiles_"), std::string::npos) << name;
      EXPECT_EQ(name.find(".tmp."), std::string::npos) << name;  // an output's (a .laz's LAS)
    }
  }
  std::string dir_;
};

TEST_F(OutOfCore, EverySharedCloudGivesTheInMemoryOutputByteForByte) {
  // (test_tiled_local_fit covers every shared cloud; here the tool's path on the kinds there
  // are: organized with colours and NaN, far from the origin, half duplicates.)
  for (const char* file : {"office1", "terrain_CSite1_red2-utm", "tutorials_room_scan1"}) {
    // The binary encodings that can be read in pieces: PCD "binary" (PCL's writer) and PLY.
    pcl::PCLPointCloud2 cloud;
    ASSERT_EQ(pcl::io::loadPCDFile(sharedData(std::string("clouds/") + file + ".pcd"), cloud), 0);
    ASSERT_EQ(pcl::PCDWriter().writeBinary(path("in.pcd"), cloud), 0);
    // A budget of 4 MiB makes tiles of about 10,000 points: up to thirty tiles here.
    expectSameOutput(path("in.pcd"), "-k 16", "4M");
  }
  saveMesh(path("in.ply"), loadMesh(sharedData("clouds/rs1.pcd")));
  expectSameOutput(path("in.ply"), "-method quadric -k 20", "4M");
  // The curvature tool's quadric path too (k1, k2, their direction, H, K, normals).
  expectSameOutput(path("in.ply"), "-method quadric -k 20", "4M", PCL_DDG_CURVATURE_TOOL);
  saveMesh(path("room.ply"), loadMesh(sharedData("clouds/tutorials_room_scan1.pcd")));
  expectSameOutput(path("room.ply"), "-radius 0.05 -max_nn 32", "3M");
  // LAS: X * scale + offset in double, written as double coordinates, from pieces of the records.
  expectSameOutput(sharedData("las/autzen_trim.las"), "-k 16", "4M");
  expectSameOutput(sharedData("las/test1_4.las"), "-method quadric -k 12", "2M",
                   PCL_DDG_CURVATURE_TOOL);
  // Robust: its wider planes read rows a dozen steps away on the noisy ground, far past the 96
  // nearest; its scale and confidence fields too.
  expectSameOutput(sharedData("las/autzen_trim.las"), "-method robust", "12M", PCL_DDG_NORMALS_TOOL,
                   "las");
  // ... and written as LAS in the input's layout (normals as Extra Bytes), from pieces.
  expectSameOutput(sharedData("las/autzen_trim.las"), "-k 16", "4M", PCL_DDG_NORMALS_TOOL, "las");
  expectSameOutput(sharedData("las/extrabytes.las"), "-method quadric -k 12", "2M",
                   PCL_DDG_CURVATURE_TOOL, "las");
  // LAZ: the pieces decoded from the chunks that hold them (autzen: three chunks of up to 50,000
  // points over eight tiles; COPC: 65 chunks of variable size, its hierarchy EVLR allowed).
  expectSameOutput(sharedData("las/laz/autzen_trim.laz"), "-k 16", "4M", PCL_DDG_NORMALS_TOOL,
                   "las");
  expectSameOutput(sharedData("las/laz/1.2-with-color.copc.laz"), "-method quadric -k 12", "2M",
                   PCL_DDG_CURVATURE_TOOL, "las");
  expectSameOutput(sharedData("las/simple.laz"), "-k 10", "2M");
  // ... and a .laz output, its LAS records compressed a chunk at a time at the end.
  expectSameOutput(sharedData("las/laz/autzen_trim.laz"), "-k 16", "4M", PCL_DDG_NORMALS_TOOL,
                   "laz");
  expectSameOutput(sharedData("las/autzen_trim_7.las"), "-method quadric -k 12", "4M",
                   PCL_DDG_CURVATURE_TOOL, "laz");
  expectNoScratchLeft();
}

TEST_F(OutOfCore, APcdOutputHoldsTheSameValuesAndStaysOrganized) {
  pcl::PCLPointCloud2 cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(sharedData("clouds/office1.pcd"), cloud), 0);
  ASSERT_EQ(pcl::PCDWriter().writeBinary(path("office.pcd"), cloud), 0);
  ASSERT_EQ(runTool(PCL_DDG_NORMALS_TOOL,
                    path("office.pcd") + " " + path("whole.pcd") + " -neighbours kdtree")
                .exit_code,
            0);
  ASSERT_EQ(
      runTool(PCL_DDG_NORMALS_TOOL, path("office.pcd") + " " + path("tiled.pcd") + " -memory 4M")
          .exit_code,
      0);
  const pcl::PolygonMesh whole = loadMesh(path("whole.pcd")), tiled = loadMesh(path("tiled.pcd"));
  EXPECT_EQ(tiled.cloud.width, 640u);
  EXPECT_EQ(tiled.cloud.height, 480u);
  ASSERT_EQ(tiled.cloud.fields.size(), whole.cloud.fields.size());
  EXPECT_TRUE(tiled.cloud.data == whole.cloud.data);
}

TEST_F(OutOfCore, InputsThatCannotBeReadInPiecesAndBadOptionsAreRefused) {
  const std::string normals = PCL_DDG_NORMALS_TOOL;
  const std::pair<std::string, std::string> refused[] = {
      // binary_compressed (one LZF block), ascii, a mesh with faces
      {sharedData("clouds/rs1.pcd"), "only an uncompressed binary PCD"},
      {sharedData("clouds/bun0.pcd"), "only an uncompressed binary PCD"},
      {sharedData("meshes/horse.ply"), "only a cloud"},
      {sharedData("meshes/cow.off"), "clouds are read in pieces"},
      {sharedData("las/laz/simple-laszip-compressor-version-1.2r0.laz"), "version 1"},
  };
  for (const auto& [input, message] : refused) {
    const ToolRun run = runTool(normals, input + " " + path("out.ply") + " -memory 64M");
    EXPECT_EQ(run.exit_code, 1) << input;
    EXPECT_NE(run.err.find(message), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(path("out.ply")));
  }
  // A .las output in pieces keeps a LAS input's layout (scale and offset): none from a PLY.
  saveMesh(path("in.ply"), loadMesh(sharedData("clouds/bun0.pcd")));
  const ToolRun to_las = runTool(normals, path("in.ply") + " " + path("out.las") + " -memory 64M");
  EXPECT_EQ(to_las.exit_code, 1);
  EXPECT_NE(to_las.err.find("needs a .las or .laz input"), std::string::npos) << to_las.err;
  EXPECT_FALSE(std::filesystem::exists(path("out.las")));
  for (const char* options : {"-memory lots", "-memory 0", "-memory 1k", "-memory 64M -radius 2h",
                              "-memory 64M -method area", "-memory 64M -neighbours rings"}) {
    EXPECT_EQ(
        runTool(normals, path("missing.pcd") + " " + path("out.ply") + " " + options).exit_code,
        std::string(options) == "-memory 1k" ? 1 : 2)
        << options;
  }
  expectNoScratchLeft();
}

// Runs the tool and returns its peak resident memory in bytes, as the tool measures itself.
std::int64_t peakMemory(const std::string& arguments) {
  const MeasuredRun run = runToolMeasured(PCL_DDG_NORMALS_TOOL, arguments);
  EXPECT_EQ(run.exit_code, 0) << arguments;
  return run.peak_bytes;
}

TEST_F(OutOfCore, StaysWithinItsBudgetWhereMemoryWouldHoldTheWholeCloud) {
  // Three million points of a torus, written as a scanner would: row after row (a tenth of it
  // under AddressSanitizer, where the peaks are not compared and the time would be long).
  const int around = kUnderAddressSanitizer ? 300 : 3000, tube = 1000;
  {
    std::ofstream out(path("torus.ply"), std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << around * tube
        << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    for (int i = 0; i < around; ++i) {
      for (int j = 0; j < tube; ++j) {
        const double u = 2 * M_PI * i / around, v = 2 * M_PI * j / tube;
        const float p[3] = {static_cast<float>((1 + 0.4 * std::cos(v)) * std::cos(u)),
                            static_cast<float>((1 + 0.4 * std::cos(v)) * std::sin(u)),
                            static_cast<float>(0.4 * std::sin(v))};
        out.write(reinterpret_cast<const char*>(p), sizeof(p));
      }
    }
  }
  const std::int64_t idle = peakMemory(sharedData("clouds/bun0.pcd") + " " + path("idle.pcd"));
  const std::int64_t whole = peakMemory(path("torus.ply") + " " + path("whole.ply"));
  constexpr std::int64_t kBudget = 48 << 20;
  const std::int64_t tiled =
      peakMemory(path("torus.ply") + " " + path("tiled.ply") + " -memory 48M");
  std::printf("%d points: peak %lld MiB in memory, %lld MiB with -memory 48M (idle %lld MiB)\n",
              around * tube, static_cast<long long>(whole >> 20),
              static_cast<long long>(tiled >> 20), static_cast<long long>(idle >> 20));
  if (!kUnderAddressSanitizer) {  // its shadow memory and quarantine make peaks meaningless
    EXPECT_LT(tiled - idle, 2 * kBudget);
    EXPECT_GT(whole, 2 * tiled);
  }
  EXPECT_TRUE(fileBytes(path("whole.ply")) == fileBytes(path("tiled.ply")));
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
