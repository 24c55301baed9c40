// LAZ (src/io/laz): the shared LAZ files of PDAL's test data decode to their uncompressed twins
// record for record (the twins were checked with laz-perf, CATALOG.md); the COPC file holds the
// same points in octree order; our encoder's files decode bit for bit to what it encoded; corrupt
// and truncated files are refused with one line, never read past their bytes.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include "io/laz/laz_codec.h"
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

template <typename T>
T at(const std::string& b, std::size_t offset) {
  T v;
  std::memcpy(&v, b.data() + offset, sizeof v);
  return v;
}

// The point records of an uncompressed LAS file, by the specification's header offsets (LAS 1.4
// R15, table 3): offset to point data (96), record length (105), legacy and 64-bit counts.
std::string recordBytes(const std::string& b) {
  const auto offset = at<std::uint32_t>(b, 96);
  const auto length = at<std::uint16_t>(b, 105);
  std::uint64_t points = at<std::uint32_t>(b, 107);
  if (b[25] >= 4 && points == 0) points = at<std::uint64_t>(b, 247);
  return b.substr(offset, points * length);
}

// readMeshFile of a LAZ file and of its twin: the same points, exact coordinates and fields.
void expectSameCloud(const std::string& laz, const std::string& las) {
  const MeshFile a = readMeshFile(laz), b = readMeshFile(las);
  ASSERT_EQ(a.positions.cols(), b.positions.cols());
  EXPECT_TRUE(a.positions == b.positions) << laz;
  ASSERT_EQ(a.mesh.cloud.fields.size(), b.mesh.cloud.fields.size());
  for (std::size_t f = 0; f < a.mesh.cloud.fields.size(); ++f)
    EXPECT_EQ(a.mesh.cloud.fields[f].name, b.mesh.cloud.fields[f].name);
  EXPECT_TRUE(a.mesh.cloud.data == b.mesh.cloud.data) << laz;
  ASSERT_TRUE(a.las && b.las);
  EXPECT_EQ(a.las->point_format, b.las->point_format);
  EXPECT_EQ(a.las->record_length, b.las->record_length);
  EXPECT_TRUE(a.las->scale == b.las->scale && a.las->offset == b.las->offset);
}

TEST(LazIO, ThePoint10FilesDecodeToTheirTwinsRecordForRecord) {
  const std::pair<const char*, const char*> twins[] = {
      {"las/laz/autzen_trim.laz", "las/autzen_trim.las"},  // 110,000 points, 3 chunks
      {"las/simple.laz", "las/1.2-with-color.las"}};       // 1,065 points
  for (const auto& [laz, las] : twins) {
    const std::string compressed = readBytes(sharedData(laz));
    const std::string twin = readBytes(sharedData(las));
    const std::string decoded = detail::lazToLas(compressed, 2);
    EXPECT_TRUE(recordBytes(decoded) == recordBytes(twin)) << laz;
    EXPECT_EQ(static_cast<std::uint8_t>(decoded[104]), static_cast<std::uint8_t>(twin[104]));
    // One thread or several: the same bytes (chunks are independent).
    EXPECT_TRUE(detail::lazToLas(compressed, 1) == decoded) << laz;
    expectSameCloud(sharedData(laz), sharedData(las));
  }
}

// The COPC file is LAS 1.4 format 7 in octree order: as a set, the points of its format-3 twin.
TEST(LazIO, TheCopcFileHoldsItsTwinsPointsInOctreeOrder) {
  const MeshFile copc = readMeshFile(sharedData("las/laz/1.2-with-color.copc.laz"));
  const MeshFile twin = readMeshFile(sharedData("las/1.2-with-color.las"));
  ASSERT_EQ(copc.positions.cols(), twin.positions.cols());
  EXPECT_EQ(copc.las->point_format, 7);
  EXPECT_TRUE(copc.las->scale == twin.las->scale);
  using Point = std::tuple<double, double, double, double, double, double, double, double>;
  const auto points = [](const MeshFile& f) {
    const Eigen::VectorXd intensity = vertexScalarField(f.mesh.cloud, "intensity");
    const Eigen::VectorXd time = vertexScalarField(f.mesh.cloud, "gps_time");
    const Eigen::VectorXd red = vertexScalarField(f.mesh.cloud, "red");
    const Eigen::VectorXd blue = vertexScalarField(f.mesh.cloud, "blue");
    const Eigen::VectorXd classification = vertexScalarField(f.mesh.cloud, "classification");
    std::vector<Point> all;
    // On the centimetre grid of both files (their offsets differ: the doubles X * scale +
    // offset may differ in their last bit).
    const auto grid = [&](int d, Eigen::Index i) {
      return static_cast<double>(std::llround(f.positions(d, i) / 0.01));
    };
    for (Eigen::Index i = 0; i < f.positions.cols(); ++i)
      all.emplace_back(grid(0, i), grid(1, i), grid(2, i), intensity[i], time[i], red[i], blue[i],
                       classification[i]);
    std::sort(all.begin(), all.end());
    return all;
  };
  EXPECT_TRUE(points(copc) == points(twin));
}

// Written out (as LAS or LAZ), a COPC file's points no longer follow its octree: its "copc"
// info VLR and hierarchy EVLR are left out, its other records kept.
TEST(LazIO, ACopcFileWrittenOutDropsItsOctreeRecords) {
  const MeshFile copc = readMeshFile(sharedData("las/laz/1.2-with-color.copc.laz"));
  const auto has = [](const std::vector<LasVariableLengthRecord>& records, const char* user) {
    return std::any_of(records.begin(), records.end(),
                       [&](const LasVariableLengthRecord& r) { return r.userId() == user; });
  };
  ASSERT_TRUE(has(copc.las->vlrs, "copc") && has(copc.las->evlrs, "copc"));
  const std::string folder = scratchFolder("laz_copc_out");
  MeshWriteOptions options;
  options.las = copc.las;
  pcl::PolygonMesh exact = copc.mesh;  // the coordinates as the tools write them: exact
  setVertexCoordinates(exact.cloud, copc.positions, FieldPrecision::Double);
  for (const char* name : {"/out.las", "/out.laz"}) {
    saveMesh(folder + name, exact, options);
    const MeshFile out = readMeshFile(folder + name);
    EXPECT_FALSE(has(out.las->vlrs, "copc") || has(out.las->evlrs, "copc")) << name;
    EXPECT_TRUE(has(out.las->vlrs, "LASF_Projection")) << name;
    EXPECT_TRUE(out.positions == copc.positions) << name;
  }
}

TEST(LazIO, TheFirstLaszipCompressorsAreRefusedWithOneLine) {
  try {
    readMeshFile(sharedData("las/laz/simple-laszip-compressor-version-1.2r0.laz"));
    FAIL() << "read";
  } catch (const FileFormatException& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("version 1"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// Our encoder (point10 v2 for formats 0-3, layered v3 for 6-8): every shared LAS file of those
// formats comes back bit for bit, header, VLRs, records and EVLRs.
TEST(LazIO, EncodedFilesDecodeBitForBit) {
  int tried = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(sharedData("las"))) {
    if (entry.path().extension() != ".las") continue;
    const std::string las = readBytes(entry.path().string());
    const int format = static_cast<std::uint8_t>(las[104]);
    if ((format > 3 && format < 6) || format > 8) continue;
    std::string laz;
    try {
      laz = detail::lasToLaz(las);
    } catch (const FileFormatException&) {
      // Only a file that is itself malformed (the clipped one claims a record it lacks).
      EXPECT_NE(entry.path().filename().string().find("clipped"), std::string::npos)
          << entry.path();
      continue;
    }
    EXPECT_LT(laz.size(), las.size() + 1024) << entry.path();
    EXPECT_TRUE(detail::lazToLas(laz, 2) == las) << entry.path();
    ++tried;
  }
  EXPECT_GE(tried, 12);
}

// Identical points compress beyond a thousand to one (here more than 128 points per byte) and
// are no lie: they decode. A layout that carries a LASzip VLR (an uncompressed file may) writes
// .las without it and .laz with its own.
TEST(LazIO, IdenticalPointsAndAStaleLaszipRecordRoundTrip) {
  const MeshFile twin = readMeshFile(sharedData("las/formats/1.2_0.las"));
  ASSERT_EQ(twin.las->point_format, 0);
  const int n = 1000000;
  pcl::PolygonMesh mesh;
  pcl::PCLPointCloud2& cloud = mesh.cloud;
  cloud = twin.mesh.cloud;
  cloud.width = n;
  cloud.height = 1;
  cloud.row_step = cloud.point_step * n;
  cloud.data.resize(static_cast<std::size_t>(n) * cloud.point_step);
  for (int i = 1; i < n; ++i)
    std::memcpy(cloud.data.data() + static_cast<std::size_t>(i) * cloud.point_step,
                cloud.data.data(), cloud.point_step);
  const Eigen::Matrix3Xd positions = twin.positions.col(0).replicate(1, n);
  setVertexCoordinates(cloud, positions, FieldPrecision::Double);
  auto layout = std::make_shared<LasLayout>(*twin.las);
  LasVariableLengthRecord laszip;
  laszip.user_id = std::string("laszip encoded").append(2, '\0');
  laszip.record_id = 22204;
  laszip.description.assign(32, '\0');
  laszip.data.assign(34, '\0');
  layout->vlrs.push_back(laszip);
  MeshWriteOptions options;
  options.las = layout;
  const std::string folder = scratchFolder("laz_identical");
  for (const char* name : {"/same.las", "/same.laz"}) {
    saveMesh(folder + name, mesh, options);
    const MeshFile back = readMeshFile(folder + name);
    EXPECT_TRUE(back.positions == positions) << name;
    EXPECT_TRUE(std::none_of(back.las->vlrs.begin(), back.las->vlrs.end(),
                             [](const LasVariableLengthRecord& r) { return r.record_id == 22204; }))
        << name;
  }
  const std::string laz = readBytes(folder + "/same.laz");
  const double point_data = static_cast<double>(laz.size() - at<std::uint32_t>(laz, 96));
  EXPECT_GT(n / point_data, 128.0) << point_data;  // the bound this file once broke
}

// A LAZ file read in pieces (the out-of-core fit, the Dask runner): each piece decodes the chunks
// holding its points, and is the piece of the uncompressed twin, field for field. Ranges within a
// chunk, across chunk ends, the whole file, in any order (a decoded run is reused or replaced).
TEST(LazIO, PiecesOfALazFileAreThePiecesOfItsTwin) {
  CloudPieceReader laz(sharedData("las/laz/autzen_trim.laz")),
      las(sharedData("las/autzen_trim.las"));
  ASSERT_EQ(laz.layout().points, 110000);
  EXPECT_EQ(laz.layout().point_bytes, las.layout().point_bytes);
  ASSERT_TRUE(laz.lasLayout() && las.lasLayout());
  EXPECT_EQ(laz.lasLayout()->vlrs.size(), las.lasLayout()->vlrs.size());
  const std::pair<std::int64_t, std::int64_t> ranges[] = {
      {0, 10},     {49990, 20},     {49990, 10}, {50000, 1}, {20000, 80000}, {0, 110000},
      {109999, 1}, {100000, 10000}, {5, 0},      {60000, 5}, {12345, 54321}};
  for (const auto& [first, count] : ranges) {
    const CloudPiece a = laz.read(first, count), b = las.read(first, count);
    ASSERT_EQ(a.positions.cols(), count) << first;
    EXPECT_TRUE(a.positions == b.positions) << first << " " << count;
    EXPECT_TRUE(a.cloud.data == b.cloud.data) << first << " " << count;
  }
  EXPECT_THROW(laz.read(109999, 2), pcl::BadArgumentException);
  // The COPC file's 65 chunks of variable size: the same points as the file read whole.
  CloudPieceReader copc(sharedData("las/laz/1.2-with-color.copc.laz"));
  const MeshFile whole = readMeshFile(sharedData("las/laz/1.2-with-color.copc.laz"));
  for (std::int64_t first = 0; first < 1065; first += 100) {
    const std::int64_t count = std::min<std::int64_t>(137, 1065 - first);
    EXPECT_TRUE(copc.read(first, count).positions == whole.positions.middleCols(first, count))
        << first;
  }
}

TEST(LazIO, AFileWithoutAUsableChunkTableIsNotReadInPieces) {
  const std::string folder = scratchFolder("laz_pieces_refused");
  std::string b = readBytes(sharedData("las/laz/autzen_trim.laz"));
  const auto point_offset = at<std::uint32_t>(b, 96);
  const std::int64_t beyond = static_cast<std::int64_t>(b.size()) + 100;
  std::memcpy(&b[point_offset], &beyond, 8);  // the table's offset past the end
  writeText(folder + "/lost.laz", b);
  try {
    CloudPieceReader reader(folder + "/lost.laz");
    ADD_FAILURE() << "read in pieces";
  } catch (const FileFormatException& e) {
    EXPECT_NE(std::string(e.what()).find("chunk table is unusable"), std::string::npos) << e.what();
  }
  // Read whole, the chunks are found one after another.
  EXPECT_EQ(readMeshFile(folder + "/lost.laz").positions.cols(), 110000);
}

// Truncated anywhere, or with a chunk table that lies, a LAZ file is refused, never read past
// its end (the sanitizer build runs this too).
TEST(LazIO, TruncatedAndLyingFilesAreRefused) {
  const std::string laz = readBytes(sharedData("las/laz/autzen_trim.laz"));
  const auto points_at = at<std::uint32_t>(laz, 96);
  for (std::size_t cut = 0; cut < laz.size(); cut += 7919) {
    EXPECT_THROW(detail::lazToLas(laz.substr(0, cut), 2), FileFormatException) << cut;
  }
  // The chunk table's offset (the first 8 bytes of the point data) past the end of the file:
  // chunks of a fixed size are found one after another without it, to the same records.
  std::string lying = laz;
  const std::uint64_t past = laz.size() + 100;
  std::memcpy(lying.data() + points_at, &past, 8);
  EXPECT_TRUE(detail::lazToLas(lying, 1) == detail::lazToLas(laz, 2));
  // ... and truncated as well: refused.
  EXPECT_THROW(detail::lazToLas(lying.substr(0, laz.size() / 2), 2), FileFormatException);
  // A point count beyond what the compressed bytes can hold is refused before anything is made.
  lying = laz;
  const std::uint32_t many = 4000000000u;
  std::memcpy(lying.data() + 107, &many, 4);
  try {
    detail::lazToLas(lying, 2);
    FAIL() << "a lying count was read";
  } catch (const FileFormatException& e) {
    EXPECT_NE(std::string(e.what()).find("LAZ"), std::string::npos) << e.what();
  }
}

// A chunk whose bytes are garbage is refused naming it, or decodes to garbage records; it never
// crashes or hangs (each chunk decodes at most its point count from at most its bytes).
TEST(LazIO, ACorruptChunkIsRefusedByIndexOrDecodedWithinItsBytes) {
  const std::string laz = readBytes(sharedData("las/laz/autzen_trim.laz"));
  int refused = 0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    std::string corrupt = laz;
    std::uint32_t state = seed * 2654435761u;
    for (int k = 0; k < 64; ++k) {
      state = state * 1664525u + 1013904223u;
      const std::size_t where = laz.size() / 3 + state % (laz.size() / 3);
      corrupt[where] = static_cast<char>(state >> 24);
    }
    try {
      const std::string decoded = detail::lazToLas(corrupt, 2);
      EXPECT_EQ(recordBytes(decoded).size(), recordBytes(detail::lazToLas(laz, 2)).size());
    } catch (const FileFormatException& e) {
      EXPECT_NE(std::string(e.what()).find("chunk"), std::string::npos) << e.what();
      ++refused;
    }
  }
  RecordProperty("refused", refused);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
