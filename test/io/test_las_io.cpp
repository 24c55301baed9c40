// LAS reading and writing (src/io/las_*.cpp) on the shared LAS files (PDAL's test data), against
// an independent reader written here from the specification's byte offsets (LAS 1.4 R15,
// tables 3 and 7-17), and on hostile headers made from them.
#include <gtest/gtest.h>

#include <pcl/common/io.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "data_catalogue.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/cloud_pieces.h"
#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

// The shared files that are whole. 1.2-with-color-clipped.las is not: its header claims 1,065
// points, but 36,405 - 229 bytes hold 1,064 records of 34 (see TruncatedSharedFileIsRefused).

template <typename T>
T at(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

template <typename T>
void setAt(std::string& bytes, std::size_t offset, T v) {
  std::memcpy(bytes.data() + offset, &v, sizeof(T));
}

// The specification's public header block, read field by field at its byte offsets.
struct SpecHeader {
  int minor = 0;
  std::uint32_t point_offset = 0, vlr_count = 0;
  int format = 0;
  std::uint16_t record_length = 0;
  std::uint64_t points = 0;
  double scale[3] = {}, offset[3] = {};
  std::uint16_t header_size = 0;
};

SpecHeader specHeader(const std::string& b) {
  SpecHeader h;
  h.minor = static_cast<std::uint8_t>(b[25]);
  h.header_size = at<std::uint16_t>(b, 94);
  h.point_offset = at<std::uint32_t>(b, 96);
  h.vlr_count = at<std::uint32_t>(b, 100);
  h.format = static_cast<std::uint8_t>(b[104]);
  h.record_length = at<std::uint16_t>(b, 105);
  h.points = h.minor >= 4 ? at<std::uint64_t>(b, 247) : at<std::uint32_t>(b, 107);
  for (int d = 0; d < 3; ++d) {
    h.scale[d] = at<double>(b, 131 + 8 * d);
    h.offset[d] = at<double>(b, 155 + 8 * d);
  }
  return h;
}

double fieldValue(const pcl::PCLPointCloud2& cloud, std::size_t i, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name != name) continue;
    const std::uint8_t* p = cloud.data.data() + i * cloud.point_step + f.offset;
    switch (f.datatype) {
      case pcl::PCLPointField::UINT8:
        return *p;
      case pcl::PCLPointField::INT8:
        return static_cast<std::int8_t>(*p);
      case pcl::PCLPointField::UINT16: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
      }
      case pcl::PCLPointField::INT16: {
        std::int16_t v;
        std::memcpy(&v, p, 2);
        return v;
      }
      case pcl::PCLPointField::UINT32: {
        std::uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
      case pcl::PCLPointField::FLOAT32: {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      }
      case pcl::PCLPointField::FLOAT64: {
        double v;
        std::memcpy(&v, p, 8);
        return v;
      }
      default:
        ADD_FAILURE() << "unexpected type of " << name;
        return 0;
    }
  }
  ADD_FAILURE() << "no field " << name;
  return 0;
}

// Every coordinate is X * scale + offset in double, and the fields are the records' fields.
TEST(LasIO, CoordinatesAndFieldsMatchTheSpecificationsOffsets) {
  for (const SharedCloud& entry : sharedLasFiles()) {
    const char* name = entry.path;
    const std::string path = sharedData(name);
    const std::string bytes = readBytes(path);
    const SpecHeader h = specHeader(bytes);
    const MeshFile file = readMeshFile(path);
    ASSERT_EQ(static_cast<std::uint64_t>(file.positions.cols()), h.points) << name;
    ASSERT_EQ(file.positions.cols(), entry.points) << name;
    ASSERT_TRUE(file.las) << name;
    EXPECT_EQ(file.coordinate_precision, FieldPrecision::Double);
    EXPECT_EQ(file.las->point_format, h.format);
    const pcl::PCLPointCloud2& cloud = file.mesh.cloud;
    const bool extended = h.format >= 6;
    for (std::uint64_t i = 0; i < h.points; ++i) {
      const std::size_t r = h.point_offset + i * h.record_length;
      for (int d = 0; d < 3; ++d) {
        const double expected = at<std::int32_t>(bytes, r + 4 * d) * h.scale[d] + h.offset[d];
        ASSERT_EQ(file.positions(d, static_cast<Eigen::Index>(i)), expected)
            << name << " point " << i << " axis " << d;
      }
      ASSERT_EQ(fieldValue(cloud, i, "x"), static_cast<float>(file.positions(0, i)));
      ASSERT_EQ(fieldValue(cloud, i, "intensity"), at<std::uint16_t>(bytes, r + 12)) << name;
      const std::uint8_t b14 = bytes[r + 14], b15 = bytes[r + 15];
      if (!extended) {
        ASSERT_EQ(fieldValue(cloud, i, "return_number"), b14 & 7);
        ASSERT_EQ(fieldValue(cloud, i, "number_of_returns"), (b14 >> 3) & 7);
        ASSERT_EQ(fieldValue(cloud, i, "classification"), b15 & 31);
        ASSERT_EQ(fieldValue(cloud, i, "scan_angle_rank"), at<std::int8_t>(bytes, r + 16));
        ASSERT_EQ(fieldValue(cloud, i, "point_source_id"), at<std::uint16_t>(bytes, r + 18));
      } else {
        ASSERT_EQ(fieldValue(cloud, i, "return_number"), b14 & 15);
        ASSERT_EQ(fieldValue(cloud, i, "number_of_returns"), b14 >> 4);
        ASSERT_EQ(fieldValue(cloud, i, "classification"), static_cast<std::uint8_t>(bytes[r + 16]));
        ASSERT_EQ(fieldValue(cloud, i, "scan_angle"), at<std::int16_t>(bytes, r + 18));
        ASSERT_EQ(fieldValue(cloud, i, "gps_time"), at<double>(bytes, r + 22));
      }
      if (h.format == 3) {
        ASSERT_EQ(fieldValue(cloud, i, "gps_time"), at<double>(bytes, r + 20));
        ASSERT_EQ(fieldValue(cloud, i, "red"), at<std::uint16_t>(bytes, r + 28));
        ASSERT_EQ(fieldValue(cloud, i, "blue"), at<std::uint16_t>(bytes, r + 32));
      }
    }
  }
}

// extrabytes.las: Colors (type 23: 3 x uint16), Reserved (type 0, 7 bytes), Flags (type 12:
// 2 x int8), Intensity (uint32), Time (uint64), after format 3's 34 bytes.
TEST(LasIO, ExtraBytesDimensionsAreFieldsByTheirDescriptions) {
  const std::string path = sharedData("las/extrabytes.las");
  const std::string bytes = readBytes(path);
  const MeshFile file = readMeshFile(path);
  ASSERT_EQ(file.las->extra_bytes.size(), 5u);
  EXPECT_EQ(file.las->undocumented_bytes, 0u);
  const pcl::PCLPointCloud2& cloud = file.mesh.cloud;
  std::map<std::string, const pcl::PCLPointField*> fields;
  for (const auto& f : cloud.fields) fields[f.name] = &f;
  ASSERT_TRUE(fields.count("Colors") && fields.count("Reserved") && fields.count("Flags") &&
              fields.count("Intensity") && fields.count("Time"));
  EXPECT_EQ(fields["Colors"]->datatype, pcl::PCLPointField::UINT16);
  EXPECT_EQ(fields["Colors"]->count, 3u);
  EXPECT_EQ(fields["Reserved"]->datatype, pcl::PCLPointField::UINT8);
  EXPECT_EQ(fields["Reserved"]->count, 7u);
  EXPECT_EQ(fields["Flags"]->datatype, pcl::PCLPointField::INT8);
  EXPECT_EQ(fields["Flags"]->count, 2u);
  EXPECT_EQ(fields["Intensity"]->datatype, pcl::PCLPointField::UINT32);
  EXPECT_EQ(fields["Time"]->datatype, pcl::PCLPointField::UINT64);
  const SpecHeader h = specHeader(bytes);
  for (std::uint64_t i = 0; i < h.points; i += 97) {
    const std::size_t r = h.point_offset + i * h.record_length;
    const std::uint8_t* p = cloud.data.data() + i * cloud.point_step;
    EXPECT_EQ(0, std::memcmp(p + fields["Colors"]->offset, bytes.data() + r + 34, 27))
        << "point " << i;
    EXPECT_EQ(fieldValue(cloud, i, "Intensity"), at<std::uint32_t>(bytes, r + 34 + 15));
  }
}

// The cloud as the tools hand it to saveMesh: exact coordinates as double x y z.
pcl::PolygonMesh asTheToolsSaveIt(const MeshFile& file) {
  pcl::PolygonMesh mesh = file.mesh;
  setVertexCoordinates(mesh.cloud, file.positions, FieldPrecision::Double);
  return mesh;
}

std::string saveLas(const std::string& path, const pcl::PolygonMesh& mesh,
                    const std::shared_ptr<const LasLayout>& las) {
  MeshWriteOptions options;
  options.las = las;
  saveMesh(path, mesh, options);
  return readBytes(path);
}

// The VLR bytes from the end of the header to the offset to the points.
std::string vlrBytes(const std::string& b) {
  const SpecHeader h = specHeader(b);
  return b.substr(h.header_size, h.point_offset - h.header_size);
}

std::string recordBytes(const std::string& b) {
  const SpecHeader h = specHeader(b);
  return b.substr(h.point_offset, h.points * h.record_length);
}

// LAS 1.4 R15 (Extra Bytes descriptor, options bits 3 and 4): value = raw * scale + offset. The
// shared file's Intensity dimension (uint32 at record byte 49) given a scale and an offset, and its
// Time dimension (uint64) one too, which doubles cannot invert exactly: it stays raw.
TEST(LasIO, ScaledExtraBytesAreRawTimesScalePlusOffset) {
  const std::string folder = scratchFolder("las_scaled_extra_bytes");
  std::string bytes = readBytes(sharedData("las/extrabytes.las"));
  for (const std::size_t d : {375 + 54 + 3 * 192, 375 + 54 + 4 * 192}) {
    bytes[d + 3] = static_cast<char>(bytes[d + 3] | 0x18);
    setAt<double>(bytes, d + 112, 0.01);
    setAt<double>(bytes, d + 136, -5.0);
  }
  std::ofstream(folder + "/a.las", std::ios::binary) << bytes;
  const MeshFile a = readMeshFile(folder + "/a.las");
  const pcl::PCLPointCloud2& cloud = a.mesh.cloud;
  const auto field = [&](const std::string& name) {
    return *std::find_if(cloud.fields.begin(), cloud.fields.end(),
                         [&](const pcl::PCLPointField& f) { return f.name == name; });
  };
  ASSERT_EQ(field("Intensity").datatype, pcl::PCLPointField::FLOAT64);
  EXPECT_EQ(field("Time").datatype, pcl::PCLPointField::UINT64);
  const SpecHeader h = specHeader(bytes);
  for (std::uint64_t i = 0; i < h.points; ++i) {
    const std::uint32_t raw = at<std::uint32_t>(bytes, h.point_offset + i * h.record_length + 49);
    ASSERT_EQ(fieldValue(cloud, i, "Intensity"), raw * 0.01 + -5.0) << "point " << i;
  }
  // Written back: the same records and VLRs, bit for bit.
  pcl::PolygonMesh mesh = asTheToolsSaveIt(a);
  std::string written = saveLas(folder + "/a2.las", mesh, a.las);
  EXPECT_EQ(vlrBytes(written), vlrBytes(bytes));
  EXPECT_EQ(recordBytes(written), recordBytes(bytes));
  // A new value is stored as round((value - offset) / scale); one beyond uint32 is refused.
  const auto setIntensity = [&](double value) {  // point 0's, in the cloud with double x y z
    for (const auto& f : mesh.cloud.fields)
      if (f.name == "Intensity") std::memcpy(mesh.cloud.data.data() + f.offset, &value, 8);
  };
  setIntensity(123 * 0.01 - 5.0);
  written = saveLas(folder + "/a3.las", mesh, a.las);
  EXPECT_EQ(at<std::uint32_t>(written, specHeader(written).point_offset + 49), 123u);
  setIntensity(-6.0);
  EXPECT_THROW(saveMesh(folder + "/a4.las", mesh,
                        [&] {
                          MeshWriteOptions o;
                          o.las = a.las;
                          return o;
                        }()),
               FileFormatException);
}

TEST(LasIO, ReadWriteReadIsBitIdenticalForRecordsAndVlrs) {
  const std::string folder = scratchFolder("las_round_trip");
  for (const SharedCloud& entry : sharedLasFiles()) {
    const char* name = entry.path;
    const std::string path = sharedData(name);
    const std::string original = readBytes(path);
    const MeshFile file = readMeshFile(path);
    const std::string out = folder + "/out.las";
    const std::string written = saveLas(out, asTheToolsSaveIt(file), file.las);
    const SpecHeader a = specHeader(original), b = specHeader(written);
    EXPECT_EQ(b.minor, a.minor) << name;
    EXPECT_EQ(b.format, a.format) << name;
    EXPECT_EQ(b.record_length, a.record_length) << name;
    EXPECT_EQ(b.points, a.points) << name;
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(b.scale[d], a.scale[d]) << name;
      EXPECT_EQ(b.offset[d], a.offset[d]) << name;
    }
    EXPECT_EQ(b.vlr_count, a.vlr_count) << name;
    EXPECT_TRUE(vlrBytes(written) == vlrBytes(original)) << name;
    EXPECT_TRUE(recordBytes(written) == recordBytes(original)) << name;
    // The identification, as read.
    EXPECT_EQ(written.substr(4, 22), original.substr(4, 22)) << name;  // source id .. version
    // Bounds recomputed: those of the points.
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(at<double>(written, 179 + 16 * d), file.positions.row(d).maxCoeff()) << name;
      EXPECT_EQ(at<double>(written, 187 + 16 * d), file.positions.row(d).minCoeff()) << name;
    }
    // And read again: the same cloud.
    const MeshFile again = readMeshFile(out);
    EXPECT_EQ(again.positions, file.positions) << name;
    EXPECT_TRUE(again.mesh.cloud.data == file.mesh.cloud.data) << name;
  }
}

// The by-return counts: what the specification's reader counts in the records.
TEST(LasIO, WrittenCountsByReturnAreTheRecords) {
  const std::string folder = scratchFolder("las_counts");
  for (const SharedCloud& entry : sharedLasFiles()) {
    const char* name = entry.path;
    const MeshFile file = readMeshFile(sharedData(name));
    const std::string written = saveLas(folder + "/c.las", asTheToolsSaveIt(file), file.las);
    const SpecHeader h = specHeader(written);
    std::uint64_t counts[15] = {};
    for (std::uint64_t i = 0; i < h.points; ++i) {
      const std::uint8_t b = written[h.point_offset + i * h.record_length + 14];
      const int r = h.format >= 6 ? (b & 15) : (b & 7);
      if (r >= 1) ++counts[r - 1];
    }
    if (h.format < 6) {
      EXPECT_EQ(at<std::uint32_t>(written, 107), h.points) << name;
      for (int r = 0; r < 5; ++r)
        EXPECT_EQ(at<std::uint32_t>(written, 111 + 4 * r), counts[r]) << name << " return " << r;
    } else {
      EXPECT_EQ(at<std::uint32_t>(written, 107), 0u) << name << ": legacy count of format 6-10";
    }
    if (h.minor >= 4) {
      for (int r = 0; r < 15; ++r)
        EXPECT_EQ(at<std::uint64_t>(written, 255 + 8 * r), counts[r]) << name << " return " << r;
    }
  }
}

// Normals and curvature as PDAL's Extra Bytes dimensions, checked against the specification's
// descriptor table (192 bytes: reserved[2], data_type, options, name[32], unused[4],
// no_data[24], min[24], max[24], scale[3], offset[3], description[32]).
TEST(LasIO, NormalsAndCurvatureAreExtraBytesDimensions) {
  const std::string folder = scratchFolder("las_extra_bytes");
  for (const char* name : {"las/autzen_trim.las", "las/extrabytes.las"}) {
    const std::string original = readBytes(sharedData(name));
    const MeshFile file = readMeshFile(sharedData(name));
    pcl::PolygonMesh mesh = asTheToolsSaveIt(file);
    const Eigen::Index n = file.positions.cols();
    Eigen::MatrixXd normals = Eigen::MatrixXd::Random(3, n);
    normals(0, 5) = std::numeric_limits<double>::quiet_NaN();
    setVertexFields(mesh.cloud, {"normal_x", "normal_y", "normal_z"}, normals);
    setVertexField(mesh.cloud, "curvature", Eigen::VectorXd::Random(n));
    const std::string written = saveLas(folder + "/n.las", mesh, file.las);
    const SpecHeader a = specHeader(original), h = specHeader(written);
    EXPECT_EQ(h.record_length, a.record_length + 16) << name;
    // The Extra Bytes VLR.
    std::size_t p = h.header_size;
    std::string extra;
    for (std::uint32_t k = 0; k < h.vlr_count; ++k) {
      const std::string user = written.substr(p + 2, 16);
      const auto id = at<std::uint16_t>(written, p + 18);
      const auto length = at<std::uint16_t>(written, p + 20);
      if (user == std::string("LASF_Spec") + std::string(7, '\0') && id == 4)
        extra = written.substr(p + 54, length);
      p += 54 + length;
    }
    ASSERT_EQ(extra.size() % 192, 0u) << name;
    const std::size_t kept = file.las->extra_bytes.size();
    ASSERT_EQ(extra.size() / 192, kept + 4) << name;
    // The input's own descriptors, byte for byte, first.
    for (std::size_t k = 0; k < kept; ++k)
      EXPECT_EQ(extra.substr(192 * k, 192), file.las->extra_bytes[k].descriptor) << name;
    const char* names[] = {"NormalX", "NormalY", "NormalZ", "Curvature"};
    for (int k = 0; k < 4; ++k) {
      const std::string d = extra.substr(192 * (kept + k), 192);
      EXPECT_EQ(d[0], 0);
      EXPECT_EQ(d[1], 0);
      EXPECT_EQ(d[2], 9) << "data type float";
      EXPECT_EQ(d[3], 0) << "options: no no_data, min, max, scale or offset";
      EXPECT_EQ(d.substr(4, 32), names[k] + std::string(32 - std::strlen(names[k]), '\0'));
      EXPECT_EQ(d.substr(36, 124), std::string(124, '\0'));  // unused .. offset: zero
    }
    // The records: the input's bytes, then the four floats.
    for (std::uint64_t i = 0; i < h.points; i += 31) {
      const std::size_t r = h.point_offset + i * h.record_length;
      const std::size_t q = a.point_offset + i * a.record_length;
      ASSERT_EQ(written.substr(r, a.record_length), original.substr(q, a.record_length));
      const float nx = at<float>(written, r + a.record_length);
      if (i == 5) {
        EXPECT_TRUE(std::isnan(nx));
      } else {
        EXPECT_EQ(nx, static_cast<float>(normals(0, i)));
      }
    }
    // Read back: the same fields under the cloud's names.
    const MeshFile again = readMeshFile(folder + "/n.las");
    EXPECT_TRUE(hasVertexField(again.mesh.cloud, "normal_x"));
    EXPECT_TRUE(hasVertexField(again.mesh.cloud, "curvature"));
    EXPECT_EQ(again.positions, file.positions);
  }
}

// The input's Extra Bytes VLR is written as it was when the fields are unchanged.
TEST(LasIO, TheSharedFilesExtraBytesVlrIsKept) {
  const std::string path = sharedData("las/extrabytes.las");
  const MeshFile file = readMeshFile(path);
  const std::string written =
      saveLas(scratchFolder("las_kept") + "/k.las", asTheToolsSaveIt(file), file.las);
  EXPECT_EQ(vlrBytes(written), vlrBytes(readBytes(path)));
}

// Found by fuzz_las: a dimension whose name has no letter ("_" would be PCL's padding, which
// writers skip) and an empty Extra Bytes VLR both survive the round trip.
TEST(LasIO, OddExtraBytesRecordsRoundTrip) {
  const std::string folder = scratchFolder("las_odd_extra_bytes");
  std::string bytes = readBytes(sharedData("las/extrabytes.las"));
  bytes[375 + 54 + 4] = '\x0e';  // "Colors" -> "\x0eolors"
  bytes[375 + 54 + 5] = '\0';
  std::ofstream(folder + "/a.las", std::ios::binary) << bytes;
  const MeshFile a = readMeshFile(folder + "/a.las");
  EXPECT_EQ(a.las->extra_bytes[0].field, "extra_0");
  std::string written = saveLas(folder + "/a2.las", asTheToolsSaveIt(a), a.las);
  EXPECT_EQ(vlrBytes(written), vlrBytes(bytes));
  EXPECT_EQ(recordBytes(written), recordBytes(bytes));
  // No descriptors: 27 undocumented bytes, the empty VLR kept.
  bytes = readBytes(sharedData("las/extrabytes.las"));
  setAt<std::uint16_t>(bytes, 375 + 20, 0);
  bytes.erase(375 + 54, 960);
  setAt<std::uint32_t>(bytes, 96, at<std::uint32_t>(bytes, 96) - 960);
  std::ofstream(folder + "/b.las", std::ios::binary) << bytes;
  const MeshFile b = readMeshFile(folder + "/b.las");
  EXPECT_EQ(b.las->undocumented_bytes, 27u);
  written = saveLas(folder + "/b2.las", asTheToolsSaveIt(b), b.las);
  EXPECT_EQ(vlrBytes(written), vlrBytes(bytes));
  EXPECT_EQ(recordBytes(written), recordBytes(bytes));
}

// A new file (from a PLY or PCD): LAS 1.4 format 6, 7 with colours; coordinates within a scale.
TEST(LasIO, ANewFileIsLas14Format6Or7) {
  const std::string folder = scratchFolder("las_new");
  Eigen::Matrix3Xd p(3, 4);
  p << 100000.125, 100001.5, 100002.25, 100000.0, -5.5, 3.25, 7.0, 0.0, 12.0, 13.5, 14.0, 12.5;
  pcl::PolygonMesh mesh = makeMesh(p, {});
  setVertexCoordinates(mesh.cloud, p, FieldPrecision::Double);
  setVertexField(mesh.cloud, "mean_curvature", Eigen::Vector4d(1, 2, 3, 4));
  std::string written = saveLas(folder + "/a.las", mesh, nullptr);
  EXPECT_EQ(written[25], 4);
  EXPECT_EQ(written[104], 6);
  MeshFile back = readMeshFile(folder + "/a.las");
  EXPECT_TRUE(back.positions.isApprox(p, 1e-12));
  EXPECT_LE((back.positions - p).cwiseAbs().maxCoeff(), 0.5 * back.las->scale.maxCoeff());
  EXPECT_TRUE(hasVertexField(back.mesh.cloud, "mean_curvature"));
  EXPECT_EQ(fieldValue(back.mesh.cloud, 0, "return_number"), 1);
  VertexColors colors(3, 4);
  colors << 0, 255, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100;
  setVertexColors(mesh.cloud, colors);
  written = saveLas(folder + "/b.las", mesh, nullptr);
  EXPECT_EQ(written[104], 7);
  back = readMeshFile(folder + "/b.las");
  EXPECT_EQ(fieldValue(back.mesh.cloud, 1, "red"), 65535);
  EXPECT_EQ(vertexColors(back.mesh.cloud), colors);
}

// A file is encoded in blocks of 2^18 points on every core, straight into a mapping of the file: a
// cloud of three blocks (the last one partial) gives the same bytes with one thread and with
// several, and the same records as the piece writer of the -memory path, which encodes a piece
// at a time and writes each after the other.
TEST(LasIO, AFileOfSeveralBlocksIsTheSameFromOneThreadOrManyOrInPieces) {
  const std::string folder = scratchFolder("las_blocks");
  const int n = 700000;
  std::mt19937 random(5);
  std::uniform_real_distribution<double> ground(0.0, 1000.0);
  Eigen::Matrix3Xd p(3, n);
  VertexColors colors(3, n);
  for (int i = 0; i < n; ++i) {
    p.col(i) << 500000.0 + ground(random), 4000000.0 + ground(random), 0.05 * ground(random);
    colors.col(i) << i % 256, (i / 256) % 256, (i * 7) % 256;
  }
  pcl::PolygonMesh mesh = makeMesh(p, {});
  setVertexCoordinates(mesh.cloud, p, FieldPrecision::Double);
  setVertexColors(mesh.cloud, colors);
#ifdef _OPENMP
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
#endif
  const std::string one = saveLas(folder + "/one.las", mesh, nullptr);
#ifdef _OPENMP
  omp_set_num_threads(std::max(2, threads));
#endif
  const std::string many = saveLas(folder + "/many.las", mesh, nullptr);
#ifdef _OPENMP
  omp_set_num_threads(threads);
#endif
  EXPECT_EQ(specHeader(one).points, static_cast<std::uint64_t>(n));
  EXPECT_TRUE(one == many);

  // In pieces of 100,000 points that do not align with the blocks, in the layout read back, with
  // the exact coordinates (as the -memory path reads them).
  const MeshFile back = readMeshFile(folder + "/one.las");
  pcl::PCLPointCloud2 cloud = back.mesh.cloud;
  setVertexCoordinates(cloud, back.positions, FieldPrecision::Double);
  CloudPieceWriter pieces(folder + "/pieces.las", "las", n, n, 1, SensorPose{}, back.las);
  for (int first = 0; first < n; first += 100000) {
    pcl::PCLPointCloud2 piece;
    piece.fields = cloud.fields;
    piece.point_step = cloud.point_step;
    piece.width = static_cast<std::uint32_t>(std::min(100000, n - first));
    piece.height = 1;
    piece.row_step = piece.point_step * piece.width;
    const auto* from = cloud.data.data() + static_cast<std::size_t>(first) * cloud.point_step;
    piece.data.assign(from, from + piece.row_step);
    pieces.write(piece);
  }
  pieces.close();
  const std::string in_pieces = readBytes(folder + "/pieces.las");
  EXPECT_TRUE(recordBytes(in_pieces) == recordBytes(one));
  // The header's stats, merged over the blocks here and over the pieces there: bounds (179-226),
  // the point count and the counts by return (247-374).
  EXPECT_EQ(in_pieces.substr(179, 48), one.substr(179, 48));
  EXPECT_EQ(in_pieces.substr(247, 128), one.substr(247, 128));
}

// LAZ is told by the compression bits of its header, whatever its name: a LAZ file named .las is
// read as LAZ (test_laz_io has the decoder's own tests).
TEST(LasIO, LazIsToldByItsHeaderNotItsName) {
  const std::string laz = sharedData("las/simple.laz");
  const std::string renamed = scratchFolder("las_laz") + "/simple.las";
  std::filesystem::copy_file(laz, renamed);
  const MeshFile a = readMeshFile(laz), b = readMeshFile(renamed);
  const MeshFile twin = readMeshFile(sharedData("las/1.2-with-color.las"));
  EXPECT_TRUE(a.positions == twin.positions);
  EXPECT_TRUE(b.positions == twin.positions);
  EXPECT_TRUE(b.mesh.cloud.data == twin.mesh.cloud.data);
}

// Hostile headers: each a shared file with one lie, refused with one line naming it.
struct Lie {
  const char* name;
  const char* file;
  void (*edit)(std::string& bytes);
  const char* message;
};

const Lie kLies[] = {
    {"legacy_count_differs_from_64_bit", "las/test1_4.las",
     [](std::string& b) { setAt<std::uint32_t>(b, 107, 999); }, "legacy point count"},
    {"64_bit_count_too_large", "las/test1_4.las",
     [](std::string& b) {
       setAt<std::uint32_t>(b, 107, 0);
       setAt<std::uint64_t>(b, 247, 1ull << 62);
     },
     "lying count"},
    {"legacy_count_too_large", "las/autzen_trim.las",
     [](std::string& b) { setAt<std::uint32_t>(b, 107, 0xffffffffu); }, "lying count"},
    {"point_offset_beyond_file", "las/autzen_trim.las",
     [](std::string& b) { setAt<std::uint32_t>(b, 96, 1u << 30); },
     "offset to the points 1073741824 is past the end of the file"},
    {"point_offset_inside_header", "las/autzen_trim.las",
     [](std::string& b) { setAt<std::uint32_t>(b, 96, 100); },
     "offset to the points 100 is inside the header (227 bytes)"},
    {"vlr_length_past_points", "las/autzen_trim.las",
     [](std::string& b) { setAt<std::uint16_t>(b, 227 + 20, 60000); }, "VLR 0"},
    {"vlr_count_past_points", "las/autzen_trim.las",
     [](std::string& b) { setAt<std::uint32_t>(b, 100, 6); }, "VLR 5"},
    {"record_length_smaller_than_format", "las/autzen_trim.las",
     [](std::string& b) { setAt<std::uint16_t>(b, 105, 20); }, "smaller than point format 3"},
    {"scale_zero", "las/autzen_trim.las", [](std::string& b) { setAt<double>(b, 139, 0.0); },
     "y scale factor 0"},
    {"scale_nan", "las/autzen_trim.las",
     [](std::string& b) { setAt<double>(b, 147, std::nan("")); }, "z scale factor"},
    {"offset_infinite", "las/autzen_trim.las",
     [](std::string& b) { setAt<double>(b, 155, INFINITY); }, "x offset"},
    {"offset_beyond_double_resolution", "las/autzen_trim.las",
     [](std::string& b) { setAt<double>(b, 163, -1.96e23); }, "finer than doubles resolve"},
    {"unknown_point_format", "las/autzen_trim.las", [](std::string& b) { b[104] = 11; },
     "point data record format 11"},
    {"version_2", "las/autzen_trim.las", [](std::string& b) { b[24] = 2; },
     "unsupported version 2.2"},
    {"header_size_too_small", "las/test1_4.las",
     [](std::string& b) { setAt<std::uint16_t>(b, 94, 227); }, "header size 227"},
    {"evlr_start_beyond_file", "las/test1_4.las",
     [](std::string& b) {
       setAt<std::uint64_t>(b, 235, 1ull << 40);
       setAt<std::uint32_t>(b, 243, 1);
     },
     "EVLRs' start"},
    {"evlr_count_past_end", "las/test1_4.las",
     [](std::string& b) {
       setAt<std::uint64_t>(b, 235, b.size());
       setAt<std::uint32_t>(b, 243, 1);
       b.append(59, '\0');  // one byte short of an EVLR header
     },
     "EVLR 0"},
    {"extra_bytes_wider_than_records", "las/extrabytes.las",
     [](std::string& b) { setAt<std::uint16_t>(b, 105, 40); }, "Extra Bytes VLR describes"},
    {"extra_bytes_unknown_type", "las/extrabytes.las", [](std::string& b) { b[375 + 54 + 2] = 31; },
     "unknown data type 31"},
    {"extra_bytes_length_not_192s", "las/extrabytes.las",
     [](std::string& b) {
       // The VLR shortened by one byte, the points moved up one (point offset - 1).
       setAt<std::uint16_t>(b, 375 + 20, 959);
       b.erase(375 + 54 + 959, 1);
       setAt<std::uint32_t>(b, 96, at<std::uint32_t>(b, 96) - 1);
     },
     "not a multiple of 192"},
    {"truncated_points", "las/autzen_trim.las", [](std::string& b) { b.resize(b.size() - 1); },
     "truncated"},
    {"truncated_header", "las/autzen_trim.las", [](std::string& b) { b.resize(200); },
     "shorter than a header"},
    {"not_las", "las/autzen_trim.las", [](std::string& b) { b[0] = 'X'; }, "no LASF signature"},
};

class HostileLasHeader : public ::testing::TestWithParam<Lie> {};

TEST_P(HostileLasHeader, IsRefusedWithOneLine) {
  const Lie& lie = GetParam();
  std::string bytes = readBytes(sharedData(lie.file));
  lie.edit(bytes);
  const std::string path = scratchFolder(std::string("las_lie_") + lie.name) + "/lie.las";
  std::ofstream(path, std::ios::binary) << bytes;
  try {
    readMeshFile(path);
    FAIL() << lie.name << " was read";
  } catch (const FileFormatException& e) {
    const std::string text = errorDescription(e);
    EXPECT_NE(text.find(lie.message), std::string::npos) << text;
    EXPECT_EQ(text.find('\n'), std::string::npos) << text;
    EXPECT_EQ(text.rfind(path, 0), 0u) << "names the file: " << text;
  }
}

INSTANTIATE_TEST_SUITE_P(Lies, HostileLasHeader, ::testing::ValuesIn(kLies),
                         [](const auto& info) { return std::string(info.param.name); });

// no-points.las (PDAL's): a valid LAS 1.2 file whose header counts no point. Refused where points
// are needed, naming the file; read as its header when asked to.
TEST(LasIO, AFileOfNoPointsIsReadAsItsHeaderOnRequest) {
  const std::string path = sharedData("las/no-points.las");
  try {
    readMeshFile(path);
    FAIL() << "a file of no points was read";
  } catch (const FileFormatException& e) {
    const std::string text = errorDescription(e);
    EXPECT_NE(text.find("no points"), std::string::npos) << text;
    EXPECT_EQ(text.rfind(path, 0), 0u) << "names the file: " << text;
  }
  const MeshFile file = readMeshFile(path, EmptyFilePolicy::Accept);
  EXPECT_EQ(file.positions.cols(), 0);
  EXPECT_EQ(file.mesh.cloud.width * file.mesh.cloud.height, 0u);
  ASSERT_TRUE(file.las);
  const std::string bytes = readBytes(path);
  const SpecHeader h = specHeader(bytes);
  ASSERT_EQ(h.points, 0u);
  EXPECT_EQ(file.las->point_format, h.format);
  EXPECT_EQ(file.las->record_length, h.record_length);
  EXPECT_EQ(file.las->vlrs.size(), h.vlr_count);
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(file.las->scale[d], h.scale[d]);
    EXPECT_EQ(file.las->offset[d], h.offset[d]);
    EXPECT_EQ(file.las->max[d], at<double>(bytes, 179 + 16 * d));
    EXPECT_EQ(file.las->min[d], at<double>(bytes, 187 + 16 * d));
  }
}

// A real file whose header claims one record more than it holds: refused, as PDAL refuses it
// ("number of points too large for file size"), with the count of whole records.
TEST(LasIO, TruncatedSharedFileIsRefused) {
  try {
    readMeshFile(sharedData("las/1.2-with-color-clipped.las"));
    FAIL() << "a truncated file was read";
  } catch (const FileFormatException& e) {
    EXPECT_NE(std::string(e.what()).find("claims 1065 points"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("holds 1064 whole records"), std::string::npos)
        << e.what();
  }
}

// Undocumented extra bytes (a record longer than its format and its descriptors) are read as
// bytes and written back in place.
TEST(LasIO, UndocumentedExtraBytesAreKept) {
  // extrabytes.las without its Extra Bytes VLR: 27 undocumented bytes per record.
  std::string bytes = readBytes(sharedData("las/extrabytes.las"));
  setAt<std::uint16_t>(bytes, 375 + 18, 77);  // no longer record 4
  const std::string folder = scratchFolder("las_undocumented");
  std::ofstream(folder + "/u.las", std::ios::binary) << bytes;
  const MeshFile file = readMeshFile(folder + "/u.las");
  EXPECT_EQ(file.las->undocumented_bytes, 27u);
  EXPECT_TRUE(hasVertexField(file.mesh.cloud, kLasUndocumentedBytesField));
  pcl::PolygonMesh mesh = asTheToolsSaveIt(file);
  setVertexField(mesh.cloud, "curvature", Eigen::VectorXd::Zero(file.positions.cols()));
  const std::string written = saveLas(folder + "/w.las", mesh, file.las);
  const SpecHeader h = specHeader(written), a = specHeader(bytes);
  EXPECT_EQ(h.record_length, 61 + 4);
  // format bytes, then the described curvature, then the undocumented bytes
  for (std::uint64_t i = 0; i < h.points; i += 50) {
    EXPECT_EQ(written.substr(h.point_offset + i * h.record_length, 34),
              bytes.substr(a.point_offset + i * a.record_length, 34));
    EXPECT_EQ(written.substr(h.point_offset + i * h.record_length + 38, 27),
              bytes.substr(a.point_offset + i * a.record_length + 34, 27));
  }
}

// Values a point format cannot hold are refused, not wrapped.
TEST(LasIO, ValuesBeyondTheFormatAreRefused) {
  const MeshFile file = readMeshFile(sharedData("las/autzen_trim.las"));
  pcl::PolygonMesh mesh = asTheToolsSaveIt(file);
  for (const auto& f : mesh.cloud.fields) {
    if (f.name == "classification") mesh.cloud.data[f.offset] = 40;
  }
  const std::string folder = scratchFolder("las_refused");
  EXPECT_THROW(saveLas(folder + "/c.las", mesh, file.las), FileFormatException);
  EXPECT_FALSE(std::filesystem::exists(folder + "/c.las"));
  mesh = asTheToolsSaveIt(file);
  Eigen::Matrix3Xd far = file.positions;
  far(0, 3) = 1e12;
  setVertexCoordinates(mesh.cloud, far, FieldPrecision::Double);
  EXPECT_THROW(saveLas(folder + "/c.las", mesh, file.las), FileFormatException);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
