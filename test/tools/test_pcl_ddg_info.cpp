// pcl_ddg_info -json on every shared mesh against the catalogue, clouds reported on their exact
// coordinates (LAS header and bounds included), exit codes and error lines.
#include <gnu/libc-version.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <array>
#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

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

Eigen::Vector3d vector3(const boost::property_tree::ptree& array) {
  Eigen::Vector3d v;
  int d = 0;
  for (const auto& item : array) v[d++] = item.second.get_value<double>();
  EXPECT_EQ(d, 3);
  return v;
}

template <typename T>
void put(std::string& bytes, std::size_t offset, T value) {
  std::memcpy(&bytes[offset], &value, sizeof(T));
}

using Record = std::array<std::int32_t, 3>;

// A LAS 1.2 file of point format 0 written from the specification's byte offsets (LAS 1.4 R15,
// table 3): the header's scale, offset and bounds as given, one 20-byte record per X Y Z.
std::string lasFile(const Eigen::Vector3d& scale, const Eigen::Vector3d& offset,
                    const Eigen::Vector3d& header_min, const Eigen::Vector3d& header_max,
                    const std::vector<Record>& records) {
  std::string bytes(227 + 20 * records.size(), '\0');
  bytes.replace(0, 4, "LASF");
  bytes[24] = 1;
  bytes[25] = 2;
  put<std::uint16_t>(bytes, 94, 227);  // header size
  put<std::uint32_t>(bytes, 96, 227);  // offset to the points
  put<std::uint16_t>(bytes, 105, 20);  // record length
  put<std::uint32_t>(bytes, 107, static_cast<std::uint32_t>(records.size()));
  for (int d = 0; d < 3; ++d) {
    put(bytes, 131 + 8 * d, scale[d]);
    put(bytes, 155 + 8 * d, offset[d]);
    put(bytes, 179 + 16 * d, header_max[d]);
    put(bytes, 187 + 16 * d, header_min[d]);
  }
  for (std::size_t i = 0; i < records.size(); ++i) {
    for (int d = 0; d < 3; ++d) put(bytes, 227 + 20 * i + 4 * d, records[i][d]);
  }
  return bytes;
}

// Survey coordinates (scale 1 mm, offset 500 km / 5000 km): float32 steps there are 1/32 and 1/2
// of a metre, so points a millimetre apart are one float, and a float box is off by up to a
// quarter of a metre.
const Eigen::Vector3d kScale(0.001, 0.001, 0.01), kOffset(500000.0, 5000000.0, 200.0);
const std::vector<Record> kRecords = {
    {123456, 7, 0}, {123457, 7, 0}, {123456, 7, 0}, {-2000, 999999, 12345}};

Eigen::Vector3d coordinates(const Record& r) {  // X * scale + offset, in double
  return Eigen::Vector3d(r[0] * kScale[0] + kOffset[0], r[1] * kScale[1] + kOffset[1],
                         r[2] * kScale[2] + kOffset[2]);
}

// The box of kRecords' coordinates: lo, hi.
void recordsBox(Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = hi = coordinates(kRecords[0]);
  for (const Record& r : kRecords) {
    lo = lo.cwiseMin(coordinates(r));
    hi = hi.cwiseMax(coordinates(r));
  }
}

TEST(PclDdgInfo, LasBoxDuplicatesAndHeaderAreTheFilesExactValues) {
  Eigen::Vector3d lo, hi;
  recordsBox(lo, hi);
  const std::string dir = scratchFolder("info_las_exact");
  writeText(dir + "/agree.las", lasFile(kScale, kOffset, lo, hi, kRecords));
  const auto j = json(dir + "/agree.las");
  EXPECT_EQ(j.get<int>("points"), 4);
  EXPECT_EQ(j.get<int>("duplicate_points"), 1) << "records 0 and 2; record 1 is 1 mm away";
  EXPECT_EQ(vector3(j.get_child("bounding_box_min")), lo);
  EXPECT_EQ(vector3(j.get_child("bounding_box_max")), hi);
  EXPECT_EQ(vector3(j.get_child("las.scale")), kScale);
  EXPECT_EQ(vector3(j.get_child("las.offset")), kOffset);
  EXPECT_EQ(vector3(j.get_child("las.header_bounds_min")), lo);
  EXPECT_EQ(vector3(j.get_child("las.header_bounds_max")), hi);
  EXPECT_EQ(j.get<std::string>("las.header_bounds_agree"), "true");
  EXPECT_TRUE(j.get_child("las.header_bounds_mismatches").empty());
  const ToolRun text = runInfo(dir + "/agree.las");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("duplicate points:  1\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("scale:             0.001 0.001 0.01\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("offset:            500000 5000000 200\n"), std::string::npos);
  EXPECT_NE(text.out.find("header vs records: agree"), std::string::npos) << text.out;
}

// A file of more points than the tool reads at once (2^19) is read a piece at a time, twice, a
// third time when the spacing is measured: its report is the whole file's. 1.2M records on a
// 1 m lattice (scale 1): the last ten repeat the first ten (duplicates pieces apart from their
// originals), classes counted in every piece, and the lattice as coarse as the spacing is said
// (the spacing's pass).
TEST(PclDdgInfo, AFileReadInPiecesIsReportedAsAWhole) {
  const int n = 1200000, row = 1200;
  std::vector<Record> records(n);
  for (int i = 0; i < n; ++i) records[i] = {i % row, i / row, (i * 7) % 5};
  for (int i = 0; i < 10; ++i) records[n - 10 + i] = records[i];
  const Eigen::Vector3d scale(1, 1, 1), offset(500000, 5000000, 200);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const Record& r : records) {
    const Eigen::Vector3d p = Eigen::Vector3d(r[0], r[1], r[2]) + offset;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::string file = lasFile(scale, offset, lo, hi, records);
  std::map<int, int> classes;
  for (int i = 0; i < n; ++i) {
    file[227 + 20 * static_cast<std::size_t>(i) + 15] = static_cast<char>(i % 3 + 1);
    ++classes[i % 3 + 1];
  }
  const std::string dir = scratchFolder("info_pieces");
  writeText(dir + "/lattice.las", file);
  const ToolRun run = runInfo(dir + "/lattice.las -json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream in(run.out);
  boost::property_tree::ptree j;
  boost::property_tree::read_json(in, j);
  EXPECT_EQ(j.get<int>("points"), n);
  EXPECT_EQ(j.get<int>("duplicate_points"), 10);
  EXPECT_EQ(vector3(j.get_child("bounding_box_min")), lo);
  EXPECT_EQ(vector3(j.get_child("bounding_box_max")), hi);
  EXPECT_EQ(j.get<std::string>("las.header_bounds_agree"), "true");
  for (const auto& [c, count] : classes)
    EXPECT_EQ(j.get_child("las.classification").get<int>(std::to_string(c)), count) << c;
  EXPECT_NE(run.err.find("a piece at a time"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("the coordinates are rounded to 1 while the points are 1 apart"),
            std::string::npos)
      << run.err;
  // The same points moved by up to 0.2 m at a millimetre's scale: no lattice.
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d)
      records[i][d] = 1000 * records[i][d] + (std::int64_t{i} * 7919 + d * 104729) % 199;
  writeText(dir + "/fine.las", lasFile(Eigen::Vector3d::Constant(0.001), offset, lo, hi, records));
  const ToolRun fine = runInfo(dir + "/fine.las");
  EXPECT_EQ(fine.err.find("rounded to"), std::string::npos) << fine.err;
}

// The levels of the COPC file's octree, from its one hierarchy page read here by the COPC
// specification's offsets (info VLR after the 375-byte header: root page offset at payload byte
// 40, size at 48; entries of 32 bytes: depth first, point count last).
TEST(PclDdgInfo, CopcOctreeAndCompressionAreReported) {
  const std::string copc = sharedData("las/laz/1.2-with-color.copc.laz");
  const std::string bytes = readBytes(copc);
  std::uint64_t root = 0, size = 0;
  std::memcpy(&root, bytes.data() + 375 + 54 + 40, 8);
  std::memcpy(&size, bytes.data() + 375 + 54 + 48, 8);
  std::map<int, std::pair<int, long long>> levels;
  for (std::uint64_t e = root; e < root + size; e += 32) {
    std::int32_t depth, points;
    std::memcpy(&depth, bytes.data() + e, 4);
    std::memcpy(&points, bytes.data() + e + 28, 4);
    ++levels[depth].first;
    levels[depth].second += points;
  }
  const auto j = json(copc);
  EXPECT_EQ(j.get<std::string>("las.storage"), "laz");
  EXPECT_EQ(j.get<std::size_t>("las.copc.nodes"), size / 32);
  EXPECT_EQ(j.get<int>("las.copc.hierarchy_pages"), 1);
  std::map<int, std::pair<int, long long>> reported;
  for (const auto& level : j.get_child("las.copc.levels"))
    reported[level.second.get<int>("depth")] = {level.second.get<int>("nodes"),
                                                level.second.get<long long>("points")};
  EXPECT_EQ(reported, levels);
  EXPECT_EQ(levels.size(), 4u);
  const ToolRun text = runInfo(copc);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("(36-byte records), compressed (LAZ)\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("COPC level 0:      1 node, "), std::string::npos) << text.out;
  // Its EVLR (the hierarchy) is listed: a file with EVLRs is read whole, not in pieces.
  EXPECT_NE(text.out.find("EVLR:              copc 1000 (2080 bytes"), std::string::npos)
      << text.out;
  EXPECT_EQ(json(sharedData("las/laz/autzen_trim.laz")).get<std::string>("las.copc"), "null");
  EXPECT_EQ(json(sharedData("las/laz/autzen_trim.laz")).get<std::string>("las.storage"), "laz");
  EXPECT_EQ(json(sharedData("las/autzen_trim.las")).get<std::string>("las.storage"), "las");
  // A hierarchy that does not hold (a node claims a point more): the file is still reported on,
  // the octree's error in its place.
  std::string lie = bytes;
  std::int32_t points = 0;
  std::memcpy(&points, lie.data() + root + 28, 4);
  ++points;
  std::memcpy(&lie[root + 28], &points, 4);
  const std::string dir = scratchFolder("info_copc_lie");
  writeText(dir + "/lie.copc.laz", lie);
  const auto j_lie = json(dir + "/lie.copc.laz");
  EXPECT_EQ(j_lie.get<int>("points"), 1065);
  EXPECT_NE(j_lie.get<std::string>("las.copc.error").find("hold 1066 points, the header 1065"),
            std::string::npos);
  const ToolRun lie_text = runInfo(dir + "/lie.copc.laz");
  EXPECT_EQ(lie_text.exit_code, 0) << lie_text.err;
  EXPECT_NE(lie_text.out.find("COPC octree:       not read: "), std::string::npos) << lie_text.out;
  EXPECT_NE(lie_text.out.find("class   2:"), std::string::npos) << lie_text.out;
}

TEST(PclDdgInfo, LasHeaderBoundsThatDisagreeWithTheRecordsAreNamed) {
  Eigen::Vector3d lo, hi;
  recordsBox(lo, hi);
  // x min 0.6 of a step above the records', y max 2.5 m above; z min 0.4 of a step below, which
  // still names the records' step.
  const Eigen::Vector3d header_min(lo.x() + 0.0006, lo.y(), lo.z() - 0.004);
  const Eigen::Vector3d header_max(hi.x(), hi.y() + 2.5, hi.z());
  const std::string dir = scratchFolder("info_las_bounds");
  writeText(dir + "/lying.las", lasFile(kScale, kOffset, header_min, header_max, kRecords));
  const auto j = json(dir + "/lying.las");
  EXPECT_EQ(vector3(j.get_child("las.header_bounds_min")), header_min);
  EXPECT_EQ(vector3(j.get_child("las.header_bounds_max")), header_max);
  EXPECT_EQ(j.get<std::string>("las.header_bounds_agree"), "false");
  struct Expected {
    std::string axis, side;
    double header, records;
  };
  const std::vector<Expected> expected = {{"x", "min", header_min.x(), lo.x()},
                                          {"y", "max", header_max.y(), hi.y()}};
  std::vector<Expected> found;
  for (const auto& item : j.get_child("las.header_bounds_mismatches")) {
    const auto& m = item.second;
    found.push_back({m.get<std::string>("axis"), m.get<std::string>("side"),
                     m.get<double>("header"), m.get<double>("records")});
    EXPECT_EQ(m.get<double>("difference"), found.back().header - found.back().records);
  }
  ASSERT_EQ(found.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(found[k].axis, expected[k].axis);
    EXPECT_EQ(found[k].side, expected[k].side);
    EXPECT_EQ(found[k].header, expected[k].header);
    EXPECT_EQ(found[k].records, expected[k].records);
  }
  const ToolRun text = runInfo(dir + "/lying.las");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("header vs records: x min differs by"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("header vs records: y max differs by"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("header vs records: z"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("agree"), std::string::npos) << text.out;
}

TEST(PclDdgInfo, DoubleCloudBoxAndDuplicatesAreTheFilesExactValues) {
  // Three points at UTM-sized coordinates a millimetre apart in x (one float32 there), two of
  // them identical.
  const std::string dir = scratchFolder("info_double_cloud");
  writeText(dir + "/utm.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
            "property double z\nend_header\n500000.001 4000000.002 10\n"
            "500000.002 4000000.002 10\n500000.001 4000000.002 10\n");
  const auto j = json(dir + "/utm.ply");
  EXPECT_EQ(j.get<int>("duplicate_points"), 1);
  EXPECT_EQ(vector3(j.get_child("bounding_box_min")), Eigen::Vector3d(500000.001, 4000000.002, 10));
  EXPECT_EQ(vector3(j.get_child("bounding_box_max")), Eigen::Vector3d(500000.002, 4000000.002, 10));
}

/** How many times the dynamic loader handed a program control in a run with LD_DEBUG=files:
 *  one start, or two when the tool started itself again. */
int programStarts(const std::string& loader_log) {
  int starts = 0;
  for (std::size_t at = loader_log.find("transferring control"); at != std::string::npos;
       at = loader_log.find("transferring control", at + 1)) {
    ++starts;
  }
  return starts;
}

/** Whether glibc.malloc.hugetlb=1 changes anything here: glibc 2.35 or later and the kernel's
 *  transparent huge pages in "madvise" mode (glibc's own condition for the tunable). */
bool hugePageTunableTakesEffect() {
  int major = 0, minor = 0;
  std::sscanf(gnu_get_libc_version(), "%d.%d", &major, &minor);
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(mode, modes);
  return (major > 2 || (major == 2 && minor >= 35)) && modes.find("[madvise]") != std::string::npos;
}

TEST(PclDdgInfo, ALargeInputRestartsTheToolOnceWithTheSameReport) {
  // tools/common/huge_pages.h: an input of 32 MiB or more, named or in an -input_dir folder,
  // makes the tool start itself again once with glibc's huge pages where they take effect; what
  // it reports is the same. A binary PLY cloud of a 1500 x 2000 grid of float points, 36 MB, and
  // its first 1,000,000 points, 12 MB.
  const std::string dir = scratchFolder("info_huge_pages");
  std::filesystem::create_directories(dir + "/folder");
  const auto writeGrid = [&](const std::string& path, int points) {
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << points
        << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    std::vector<float> xyz;
    xyz.reserve(3 * static_cast<std::size_t>(points));
    for (int i = 0; i < points; ++i) {
      const float x = static_cast<float>(i % 1500) * 0.01f,
                  y = static_cast<float>(i / 1500) * 0.01f;
      xyz.insert(xyz.end(), {x, y, 0.25f * x - 0.5f * y});
    }
    out.write(reinterpret_cast<const char*>(xyz.data()),
              static_cast<std::streamsize>(xyz.size() * sizeof(float)));
  };
  writeGrid(dir + "/large.ply", 1500 * 2000);
  writeGrid(dir + "/folder/large.ply", 1500 * 2000);
  writeGrid(dir + "/small.ply", 1000000);
  // The runs see only the environment given here, whatever the test's own holds.
  const auto run = [](const std::string& settings, const std::string& arguments) {
    return runTool("env -u PCL_DDG_HUGE_PAGES -u GLIBC_TUNABLES -u LD_DEBUG_OUTPUT " + settings +
                       " LD_DEBUG=files " + PCL_DDG_INFO_TOOL,
                   arguments);
  };
  const ToolRun large = run("", dir + "/large.ply");
  const ToolRun large_small_pages = run("PCL_DDG_HUGE_PAGES=0", dir + "/large.ply");
  const ToolRun users_choice = run("GLIBC_TUNABLES=glibc.malloc.hugetlb=0", dir + "/large.ply");
  const ToolRun small = run("", dir + "/small.ply");
  const ToolRun folder = run("", "-input_dir " + dir + "/folder");
  for (const ToolRun* done : {&large, &large_small_pages, &users_choice, &small, &folder}) {
    ASSERT_EQ(done->exit_code, 0) << done->err.substr(
        done->err.size() > 600 ? done->err.size() - 600 : 0);
  }
  const int restarted = hugePageTunableTakesEffect() ? 2 : 1;
  EXPECT_EQ(programStarts(large.err), restarted);
  EXPECT_EQ(programStarts(folder.err), restarted);
  EXPECT_EQ(programStarts(large_small_pages.err), 1);
  EXPECT_EQ(programStarts(users_choice.err), 1);
  EXPECT_EQ(programStarts(small.err), 1);
  EXPECT_NE(large.out.find("3000000"), std::string::npos) << large.out;
  EXPECT_EQ(large.out, large_small_pages.out);
  EXPECT_EQ(large.out, users_choice.out);
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
