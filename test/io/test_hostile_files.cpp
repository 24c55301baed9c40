// Files made to crash, hang or exhaust a loader (each seen in an attack on the tools): every one
// must fail with a FileFormatException naming the problem, at a cost of a small multiple of its
// size. Each case is a tiny file written by the test.
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>

#include <cstdint>
#include <cstring>
#include <filesystem>

#include "data_catalogue.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"
#include "tool_runner.h"

namespace pcl_ddg {
namespace test {
namespace {

// Beyond the resident peak: a loader that reserves (without touching) a size a lying header
// names fails under this limit instead of passing unseen. (ASan reserves terabytes of shadow
// address space: no limit there.)
constexpr std::uint64_t kAddressLimit = kUnderAddressSanitizer ? 0 : std::uint64_t(2) << 30;

// Peak resident memory (MiB) of pcl_ddg_info loading a file, as the tool measures itself: a
// process of its own, so that an allocation storm cannot take the test runner down; -1 if it
// crashed (exit 0 = loaded, 1 = refused).
long peakMiBOfLoading(const std::string& path) {
  const MeasuredRun run = runToolMeasured(PCL_DDG_INFO_TOOL, "'" + path + "'", kAddressLimit);
  if (run.exit_code < 0 || run.exit_code > 1 || run.peak_bytes < 0) return -1;
  return static_cast<long>(run.peak_bytes >> 20);
}

template <typename T>
std::string bytesOf(T value, bool big_endian = false) {
  std::string bytes(sizeof(T), '\0');
  std::memcpy(bytes.data(), &value, sizeof(T));
  if (big_endian) std::reverse(bytes.begin(), bytes.end());
  return bytes;
}

class HostileFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
    baseline_mib_ =
        peakMiBOfLoading(write("tiny.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  }
  std::string write(const std::string& name, const std::string& content) const {
    const std::string path = dir_ + "/" + name;
    writeText(path, content);
    return path;
  }
  // The file is refused with a message containing `expected`, without a crash and without
  // costing more than 64 MiB over an idle child.
  void expectRefused(const std::string& name, const std::string& content,
                     const std::string& expected) const {
    SCOPED_TRACE(name);
    const std::string path = write(name, content);
    try {
      loadMesh(path);
      ADD_FAILURE() << "loaded without error";
    } catch (const FileFormatException& e) {
      const std::string message = errorDescription(e);
      EXPECT_NE(message.find(expected), std::string::npos) << message;
      EXPECT_EQ(message.find(": :"), std::string::npos) << message;
      EXPECT_EQ(message.rfind(path, 0), 0u) << message;  // starts with the file's name
    }
    const long peak = peakMiBOfLoading(path);
    EXPECT_GE(peak, 0) << "the loader crashed";
    EXPECT_LT(peak, baseline_mib_ + 64) << "MiB for a " << content.size() << "-byte file";
  }
  std::string dir_;
  long baseline_mib_ = 0;
};

const std::string kPlyVertexHeader =
    "ply\nformat binary_little_endian 1.0\nelement vertex 357913942\n"
    "property float x\nproperty float y\nproperty float z\nend_header\n";

TEST_F(HostileFiles, PlyVertexCountsThatWrapOrExceedTheFile) {
  // 357913942 x 12 bytes wraps a 32-bit row_step to 8; this once wrote past the buffer.
  expectRefused("wrap.ply", kPlyVertexHeader + std::string(24, '\0'), "more than the file holds");
  std::string huge = kPlyVertexHeader;
  huge.replace(huge.find("357913942"), 9, "4294967297");
  expectRefused("huge.ply", huge + std::string(24, '\0'), "more than the file holds");
  expectRefused("intmax.ply",
                "ply\nformat ascii 1.0\nelement vertex 2147483647\nproperty float x\n"
                "property float y\nproperty float z\nend_header\n0 0 0\n",
                "more than the file holds");
  expectRefused("nopropertiesvertices.ply",
                "ply\nformat ascii 1.0\nelement vertex 1000000000000\nend_header\n",
                "no properties");
}

TEST_F(HostileFiles, PlyListLengthsThatExceedTheFile) {
  // 187 bytes asking for a face of 10^9 corners (was 7.8 GB).
  expectRefused("biglist.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uint int vertex_indices\n"
                "end_header\n0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n",
                "invalid list length");
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
      "element face 1\nproperty list uint int vertex_indices\nend_header\n";
  binary += bytesOf<std::uint32_t>(4000000000u) + std::string(12, '\0');
  expectRefused("biglist_binary.ply", binary, "invalid list length");
}

TEST_F(HostileFiles, PlyValuesOutsideTheirTypeAreRefusedWithTheLine) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty uchar x\nproperty float y\n"
      "property float z\nend_header\n1 0 0\n";
  expectRefused("uchar300.ply", header + "300 0 0\n", "line 9: value 300 is out of range");
  expectRefused("ucharneg.ply", header + "-5 0 0\n", "line 9: value -5 is out of range");
  expectRefused("uchar1e30.ply", header + "1e30 0 0\n", "out of range");
  expectRefused("ucharfrac.ply", header + "1.5 0 0\n", "out of range");
  expectRefused("float1e300.ply", header + "1 1e300 0\n", "line 9: value 1e+300 is out of range");
  expectRefused("float_index.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar float vertex_indices\n"
                "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1e30\n",
                "out of range for a vertex index");
}

// Fuzzer finding (fuzz_ply, heap-buffer-overflow): a second vertex element appended its fields
// to the first one's, and the range grid then wrote NaNs past each point.
TEST_F(HostileFiles, PlyWithTwoVertexElementsIsRefused) {
  expectRefused("twovertex.ply",
                "ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 1\n"
                "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                "element vertex 1\nproperty double w\nelement range_grid 2\n"
                "property list uchar int vertex_indices\nend_header\n0 0 0\n5\n1 0\n0\n",
                "second vertex element");
}

TEST_F(HostileFiles, PlyRangeGridSizesThatOverflow) {
  expectRefused("grid.ply",
                "ply\nformat ascii 1.0\nobj_info num_cols 4611686018427387904\n"
                "obj_info num_rows 4\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nelement range_grid 1\nproperty list uchar int vertex_indices\n"
                "end_header\n0 0 0\n1 0\n",
                "range_grid size");
}

const std::string kPcdHeader =
    "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
    "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST_F(HostileFiles, PcdHeadersThatLie) {
  const std::string body = "DATA binary\n" + std::string(24, '\0');
  expectRefused("count_negative.pcd", replaced(kPcdHeader, "COUNT 1 1 1", "COUNT 1 1 -1") + body,
                "COUNT -1 is out of range");
  expectRefused("count_huge.pcd",
                replaced(kPcdHeader, "COUNT 1 1 1", "COUNT 1 1 2147483648") + body, "out of range");
  expectRefused("points.pcd", replaced(kPcdHeader, "POINTS 2", "POINTS 3") + body,
                "is not WIDTH x HEIGHT");
  expectRefused("width.pcd",
                replaced(replaced(kPcdHeader, "WIDTH 2", "WIDTH 4294967295"), "POINTS 2",
                         "POINTS 4294967295") +
                    body,
                "shorter than POINTS");
  expectRefused("width_overflow.pcd",
                replaced(replaced(kPcdHeader, "WIDTH 2", "WIDTH 4294967295"), "HEIGHT 1",
                         "HEIGHT 4294967295") +
                    body,
                "impossible WIDTH x HEIGHT");
  expectRefused("size.pcd", replaced(kPcdHeader, "SIZE 4 4 4", "SIZE 4 4 3") + body,
                "unsupported PCD field type F of size 3");
  expectRefused("truncated.pcd", kPcdHeader + "DATA binary\n" + std::string(23, '\0'),
                "shorter than POINTS");
  expectRefused("ascii_short.pcd", kPcdHeader + "DATA ascii\n1 2 3" + std::string(20, ' ') + "\n",
                "fewer rows than POINTS");
  // A megabyte per point claimed by COUNT, in a file of a few bytes.
  expectRefused("ascii_count.pcd",
                replaced(replaced(kPcdHeader, "COUNT 1 1 1", "COUNT 1 1 1048576"), "SIZE 4 4 4",
                         "SIZE 4 4 8") +
                    "DATA ascii\n1 2 3\n1 2 3\n",
                "shorter than POINTS");
  expectRefused("ascii_range.pcd",
                replaced(kPcdHeader, "TYPE F F F", "TYPE F F U") + "DATA ascii\n1 2 3\n1 2 -3\n",
                "out of range");
}

TEST_F(HostileFiles, PcdCompressedSizesThatLie) {
  const std::string header = kPcdHeader + "DATA binary_compressed\n";
  expectRefused("zero.pcd", header + bytesOf<std::uint32_t>(4) + bytesOf<std::uint32_t>(0) + "abcd",
                "uncompressed size 0 is not");
  expectRefused("empty.pcd", header + bytesOf<std::uint32_t>(0) + bytesOf<std::uint32_t>(24),
                "compressed data is empty");
  expectRefused(
      "corrupt.pcd",
      header + bytesOf<std::uint32_t>(4) + bytesOf<std::uint32_t>(24) + "\xff\xff\xff\xff",
      "corrupt");
  expectRefused("beyond.pcd",
                header + bytesOf<std::uint32_t>(100) + bytesOf<std::uint32_t>(24) + "abcd",
                "unexpected end of file");
  const std::string absurd =
      replaced(replaced(header, "WIDTH 2", "WIDTH 1000000000"), "POINTS 2", "POINTS 1000000000");
  expectRefused("absurd.pcd",
                absurd + bytesOf<std::uint32_t>(4) + bytesOf<std::uint32_t>(24) + "abcd",
                "shorter than POINTS");
}

TEST_F(HostileFiles, OffCountsThatExceedTheFile) {
  expectRefused("faces.off", "OFF\n3 900000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "larger than the file can hold");
  expectRefused("facesize.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4611686018427387904 0 1 2\n",
                "does not fit its line");
  std::string binary = "OFF BINARY\n";
  for (std::int32_t n : {3, 900000000, 0}) binary += bytesOf(n, true);
  expectRefused("faces_binary.off", binary + std::string(36, '\0'), "neither byte order");
}

TEST_F(HostileFiles, BinaryOffIsReadInBothByteOrders) {
  for (const bool big : {true, false}) {
    std::string data = "OFF BINARY\n";
    for (std::int32_t n : {3, 1, 0}) data += bytesOf(n, big);
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 2.f, 0.f}) data += bytesOf(v, big);
    for (std::int32_t n : {3, 0, 1, 2, 0}) data += bytesOf(n, big);
    const pcl::PolygonMesh mesh = loadMesh(write(big ? "big.off" : "little.off", data));
    ASSERT_EQ(mesh.polygons.size(), 1u);
    EXPECT_EQ(vertexPositions(mesh.cloud).col(2), Eigen::Vector3d(0, 2, 0));
  }
}

TEST_F(HostileFiles, VtkCountsThatOverflow) {
  expectRefused("points.vtk",
                "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n"
                "POINTS 4611686018427387904 float\n0 0 0\n",
                "impossible point count");
  expectRefused("offsets.vtk",
                "# vtk DataFile Version 5.1\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n"
                "0 0 0 1 0 0 0 1 0\nPOLYGONS 2 3\nOFFSETS vtktypeint64\n0 1e30\n"
                "CONNECTIVITY vtktypeint64\n0 1 2\n",
                "out of range for a VTK cell index");
}

TEST_F(HostileFiles, OnlyRegularFilesAreRead) {
  for (const char* device : {"/dev/zero", "/dev/null"}) {
    SCOPED_TRACE(device);
    std::filesystem::create_symlink(device, dir_ + "/device.ply");
    try {
      loadMesh(dir_ + "/device.ply");
      ADD_FAILURE() << "a device was read";
    } catch (const FileFormatException& e) {
      EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
    std::filesystem::remove(dir_ + "/device.ply");
  }
  std::filesystem::create_directory(dir_ + "/folder.ply");
  try {
    loadMesh(dir_ + "/folder.ply");
    ADD_FAILURE() << "a directory was read";
  } catch (const FileFormatException& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  try {
    loadMesh(write("noextension", "OFF\n"));
    ADD_FAILURE();
  } catch (const FileFormatException& e) {
    EXPECT_NE(std::string(e.what()).find("no file extension"), std::string::npos) << e.what();
  }
}

// Our PCD reader against PCL's on every shared cloud (PCL's is trusted on well-formed files),
// and on binary_compressed files that PCL's writer makes.
TEST_F(HostileFiles, PcdReaderAgreesWithPclOnWellFormedFiles) {
  for (const SharedCloud& cloud : sharedClouds()) {
    const std::string name = std::string(cloud.path).substr(7);  // after clouds/
    SCOPED_TRACE(name);
    pcl::PCLPointCloud2 expected;
    ASSERT_EQ(pcl::PCDReader().read(sharedData(std::string("clouds/") + name), expected), 0);
    pcl::PCDWriter writer;
    const std::string compressed = dir_ + "/compressed_" + name;
    ASSERT_EQ(writer.writeBinaryCompressed(compressed, expected), 0);
    for (const std::string& path : {sharedData(std::string("clouds/") + name), compressed}) {
      const pcl::PCLPointCloud2 ours = loadMesh(path).cloud;
      EXPECT_EQ(ours.width, expected.width);
      EXPECT_EQ(ours.height, expected.height);
      EXPECT_EQ(ours.point_step, expected.point_step);
      ASSERT_EQ(ours.fields.size(), expected.fields.size());
      for (std::size_t f = 0; f < ours.fields.size(); ++f) {
        EXPECT_EQ(ours.fields[f].name, expected.fields[f].name);
        EXPECT_EQ(ours.fields[f].offset, expected.fields[f].offset);
        EXPECT_EQ(ours.fields[f].datatype, expected.fields[f].datatype);
        EXPECT_EQ(ours.fields[f].count, expected.fields[f].count);
      }
      // Byte for byte, except padding ("_") which PCL's compressed writer does not store.
      const Eigen::Matrix3Xd a = vertexPositions(ours, NonFinitePolicy::Keep);
      const Eigen::Matrix3Xd b = vertexPositions(expected, NonFinitePolicy::Keep);
      EXPECT_TRUE(((a.array() == b.array()) || (a.array().isNaN() && b.array().isNaN())).all());
      bool has_padding = false;
      for (const auto& f : ours.fields) has_padding |= f.name == "_";
      if (!has_padding) EXPECT_EQ(ours.data, expected.data);
    }
  }
}

TEST_F(HostileFiles, PcdViewpointIsKeptFromInputToOutput) {
  SensorPose pose;
  const pcl::PolygonMesh office = loadMesh(sharedData("clouds/office1.pcd"), &pose);
  EXPECT_EQ(pose.origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(pose.orientation.coeffs(),
            Eigen::Vector4d(1, 0, 0, 0));  // x y z w: "0 1 0 0" in w x y z
  pose.origin = Eigen::Vector3d(512600.25, 5403580.5, 1000.125);
  MeshWriteOptions options;
  options.sensor_pose = pose;
  const std::string path = dir_ + "/office.pcd";
  saveMesh(path, office, options);
  SensorPose back;
  loadMesh(path, &back);
  EXPECT_EQ(back.origin, pose.origin);
  EXPECT_EQ(back.orientation.coeffs(), pose.orientation.coeffs());
  pcl::PCLPointCloud2 by_pcl;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0;
  ASSERT_EQ(pcl::PCDReader().read(path, by_pcl, origin, orientation, version), 0);
  EXPECT_EQ(origin.head<3>(), pose.origin.cast<float>());
  EXPECT_EQ(orientation.coeffs(), pose.orientation.coeffs().cast<float>());
  expectRefused("viewpoint.pcd",
                replaced(kPcdHeader, "VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0 0 0 0 0 0") +
                    "DATA ascii\n0 0 0\n1 1 1\n",
                "VIEWPOINT needs");
}

// What we write, PCL's reader reads back to the same values (and so do we).
TEST_F(HostileFiles, PcdWriterOutputIsReadByPcl) {
  for (const char* name : {"bun0.pcd", "office1.pcd", "terrain_CSite1_red2-utm.pcd"}) {
    SCOPED_TRACE(name);
    const pcl::PolygonMesh original = loadMesh(sharedData(std::string("clouds/") + name));
    const std::string path = dir_ + "/out.pcd";
    saveMesh(path, original);
    pcl::PCLPointCloud2 by_pcl;
    ASSERT_EQ(pcl::PCDReader().read(path, by_pcl), 0);
    EXPECT_EQ(by_pcl.width, original.cloud.width);
    EXPECT_EQ(by_pcl.height, original.cloud.height);
    EXPECT_EQ(by_pcl.data, original.cloud.data);
    EXPECT_EQ(loadMesh(path).cloud.data, original.cloud.data);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
