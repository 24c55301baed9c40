// Loading and saving the 1.15M-vertex bench torus, as the tools do, against PCL's own readers and
// writer in the same run:
//   load_ascii_off   readMeshFile on an ascii OFF (%.9g)    vs a textbook iostream >> loader
//   load_binary_ply  readMeshFile on a binary PLY            vs pcl::io::loadPLYFile
//   load_ascii_ply   readMeshFile on an ascii PLY            vs pcl::io::loadPLYFile
//   save_binary_ply  saveMesh                                vs pcl::io::savePLYFileBinary
// and a 10M-point LAS 1.4 point format 7 survey (made here: a gently rolling terrain, scale 1 mm,
// every format 7 field set) against a binary PCD (DATA binary, F 8 x y z) of the same points and
// fields, in the same run, in MB/s of each file and million points per second:
//   las/read           readMeshFile on the .las              vs pcd_binary/read: readMeshFile on
//                                                               the binary .pcd
//   las/write          saveMesh to .las (the layout kept)    vs pcd_binary/write:
//                                                               pcl::PCDWriter::writeBinary
// (the ratio printed is LAS's time over PCD's for the same points: below 1 is LAS faster). Set
// PCL_DDG_BENCH_LAS_POINTS for another size.
// The files are written once into a temporary folder.
#include <benchmark/benchmark.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "bench_support.h"
#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/mesh_io.h"

namespace pcl_ddg {
namespace bench {
namespace {

struct MeshFiles {
  std::string dir, ascii_off, binary_ply, ascii_ply;
  pcl::PolygonMesh mesh;
};

const MeshFiles& files() {
  static const MeshFiles f = [] {
    MeshFiles f;
    f.dir = (std::filesystem::temp_directory_path() / "pcl_ddg_bench_mesh_io").string();
    std::filesystem::create_directories(f.dir);
    f.ascii_off = f.dir + "/torus.off";
    f.binary_ply = f.dir + "/torus_binary.ply";
    f.ascii_ply = f.dir + "/torus_ascii.ply";
    const BenchMesh& torus = torusMesh(1600, 720);
    pcl::PointCloud<pcl::PointXYZ> points;
    for (Eigen::Index v = 0; v < torus.points.cols(); ++v) {
      const Eigen::Vector3f p = torus.points.col(v).cast<float>();
      points.push_back({p.x(), p.y(), p.z()});
    }
    pcl::toPCLPointCloud2(points, f.mesh.cloud);
    f.mesh.polygons.resize(torus.triangles.cols());
    for (Eigen::Index t = 0; t < torus.triangles.cols(); ++t) {
      f.mesh.polygons[t].vertices = {torus.triangles(0, t), torus.triangles(1, t),
                                     torus.triangles(2, t)};
    }
    saveMesh(f.binary_ply, f.mesh, {PlyEncoding::Binary});
    saveMesh(f.ascii_ply, f.mesh, {PlyEncoding::Ascii});
    std::FILE* off = std::fopen(f.ascii_off.c_str(), "w");
    std::fprintf(off, "OFF\n%zu %zu 0\n", points.size(), f.mesh.polygons.size());
    for (const pcl::PointXYZ& p : points) std::fprintf(off, "%.9g %.9g %.9g\n", p.x, p.y, p.z);
    for (const pcl::Vertices& face : f.mesh.polygons) {
      std::fprintf(off, "3 %d %d %d\n", face.vertices[0], face.vertices[1], face.vertices[2]);
    }
    std::fclose(off);
    return f;
  }();
  return f;
}

void load(benchmark::State& state, std::string MeshFiles::*path) {
  const std::string& file = files().*path;
  for (auto _ : state) benchmark::DoNotOptimize(readMeshFile(file));
  state.counters["MB/s"] =
      benchmark::Counter(static_cast<double>(std::filesystem::file_size(file)) / 1e6,
                         benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK_CAPTURE(load, off, &MeshFiles::ascii_off)
    ->Name("ours/load_ascii_off")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(load, binary_ply, &MeshFiles::binary_ply)
    ->Name("ours/load_binary_ply")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(load, ascii_ply, &MeshFiles::ascii_ply)
    ->Name("ours/load_ascii_ply")
    ->Unit(benchmark::kMillisecond);

void pclLoadPly(benchmark::State& state, std::string MeshFiles::*path) {
  const std::string& file = files().*path;
  for (auto _ : state) {
    pcl::PolygonMesh mesh;
    if (pcl::io::loadPLYFile(file, mesh) != 0) state.SkipWithError("PCL could not read the file");
    benchmark::DoNotOptimize(mesh);
  }
}
BENCHMARK_CAPTURE(pclLoadPly, binary_ply, &MeshFiles::binary_ply)
    ->Name("baseline/load_binary_ply")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(pclLoadPly, ascii_ply, &MeshFiles::ascii_ply)
    ->Name("baseline/load_ascii_ply")
    ->Unit(benchmark::kMillisecond);

// What a hand-written OFF reader usually is: std::ifstream and operator>>.
void iostreamLoadOff(benchmark::State& state) {
  for (auto _ : state) {
    std::ifstream in(files().ascii_off);
    std::string magic;
    std::size_t vertices = 0, faces = 0, edges = 0;
    in >> magic >> vertices >> faces >> edges;
    pcl::PointCloud<pcl::PointXYZ> points(static_cast<std::uint32_t>(vertices), 1);
    for (pcl::PointXYZ& p : points) in >> p.x >> p.y >> p.z;
    pcl::PolygonMesh mesh;
    mesh.polygons.resize(faces);
    for (pcl::Vertices& face : mesh.polygons) {
      std::size_t corners = 0;
      in >> corners;
      face.vertices.resize(corners);
      for (pcl::index_t& corner : face.vertices) in >> corner;
    }
    pcl::toPCLPointCloud2(points, mesh.cloud);
    benchmark::DoNotOptimize(mesh);
  }
}
BENCHMARK(iostreamLoadOff)->Name("baseline/load_ascii_off")->Unit(benchmark::kMillisecond);

void saveBinaryPly(benchmark::State& state) {
  const std::string out = files().dir + "/saved.ply";
  for (auto _ : state) saveMesh(out, files().mesh, {PlyEncoding::Binary});
}
BENCHMARK(saveBinaryPly)->Name("ours/save_binary_ply")->Unit(benchmark::kMillisecond);

void pclSaveBinaryPly(benchmark::State& state) {
  const std::string out = files().dir + "/saved_pcl.ply";
  for (auto _ : state) pcl::io::savePLYFileBinary(out, files().mesh);
}
BENCHMARK(pclSaveBinaryPly)->Name("baseline/save_binary_ply")->Unit(benchmark::kMillisecond);

// --- LAS 1.4 format 7 against binary PCD on the same points ----------------------------------

struct LasFiles {
  std::string las, pcd;
  std::size_t points = 0;
  pcl::PolygonMesh cloud;  ///< double x y z and every format 7 field
  std::shared_ptr<LasLayout> layout;
};

const LasFiles& lasFiles() {
  static const LasFiles f = [] {
    LasFiles f;
    f.points = 10'000'000;
    if (const char* n = std::getenv("PCL_DDG_BENCH_LAS_POINTS")) f.points = std::stoull(n);
    f.las = files().dir + "/survey.las";
    f.pcd = files().dir + "/survey.pcd";
    using F = pcl::PCLPointField;
    struct Field {
      const char* name;
      std::uint8_t type;
    };
    const Field fields[] = {{"x", F::FLOAT64},
                            {"y", F::FLOAT64},
                            {"z", F::FLOAT64},
                            {"intensity", F::UINT16},
                            {"return_number", F::UINT8},
                            {"number_of_returns", F::UINT8},
                            {"classification_flags", F::UINT8},
                            {"scanner_channel", F::UINT8},
                            {"scan_direction_flag", F::UINT8},
                            {"edge_of_flight_line", F::UINT8},
                            {"classification", F::UINT8},
                            {"user_data", F::UINT8},
                            {"scan_angle", F::INT16},
                            {"point_source_id", F::UINT16},
                            {"gps_time", F::FLOAT64},
                            {"red", F::UINT16},
                            {"green", F::UINT16},
                            {"blue", F::UINT16}};
    pcl::PCLPointCloud2& c = f.cloud.cloud;
    std::uint32_t step = 0;
    for (const Field& field : fields) {
      pcl::PCLPointField pf;
      pf.name = field.name;
      pf.offset = step;
      pf.datatype = field.type;
      pf.count = 1;
      c.fields.push_back(pf);
      step += static_cast<std::uint32_t>(pcl::getFieldSize(field.type));
    }
    c.width = static_cast<std::uint32_t>(f.points);
    c.height = 1;
    c.point_step = step;
    c.row_step = step * c.width;
    c.is_dense = true;
    c.data.resize(f.points * step);
    // A 5 km x 2 km strip of rolling ground at 1 mm, UTM-like offsets, 1-4 returns.
    const std::size_t side = static_cast<std::size_t>(std::sqrt(2.5 * f.points)) + 1;
    for (std::size_t i = 0; i < f.points; ++i) {
      std::uint8_t* p = c.data.data() + i * step;
      const double u = static_cast<double>(i % side), v = static_cast<double>(i / side);
      // X * scale + offset, as a LAS reader computes it from the integers
      const double x = std::round(u * 5000.0 / side * 1000.0) * 0.001 + 500000.0;
      const double y = std::round(v * 5000.0 / side * 1000.0) * 0.001 + 4000000.0;
      const double z =
          std::round((120.0 + 8.0 * std::sin(u * 0.01) * std::cos(v * 0.013)) * 1000.0) * 0.001 +
          0.0;
      const std::uint8_t returns = static_cast<std::uint8_t>(1 + i % 4);
      const std::uint8_t bytes[] = {static_cast<std::uint8_t>(1 + (i / 4) % returns),
                                    returns,
                                    static_cast<std::uint8_t>(i % 3 == 0 ? 1 : 0),
                                    static_cast<std::uint8_t>(i % 2),
                                    static_cast<std::uint8_t>((i / side) % 2),
                                    static_cast<std::uint8_t>(i % side == 0 ? 1 : 0),
                                    static_cast<std::uint8_t>(i % 7 == 0 ? 6 : 2),
                                    static_cast<std::uint8_t>(i % 251)};
      const std::int16_t angle = static_cast<std::int16_t>(static_cast<int>(i % 5000) - 2500);
      const std::uint16_t source = static_cast<std::uint16_t>(1 + (i / side) / 100);
      const double gps = 2.0e8 + static_cast<double>(i) * 1e-5;
      const std::uint16_t intensity = static_cast<std::uint16_t>(i * 2654435761u >> 16);
      const std::uint16_t rgb[] = {static_cast<std::uint16_t>((i * 97) & 0xFFFF),
                                   static_cast<std::uint16_t>((i * 89) & 0xFFFF),
                                   static_cast<std::uint16_t>((i * 83) & 0xFFFF)};
      std::memcpy(p, &x, 8);
      std::memcpy(p + 8, &y, 8);
      std::memcpy(p + 16, &z, 8);
      std::memcpy(p + 24, &intensity, 2);
      std::memcpy(p + 26, bytes, 8);
      std::memcpy(p + 34, &angle, 2);
      std::memcpy(p + 36, &source, 2);
      std::memcpy(p + 38, &gps, 8);
      std::memcpy(p + 46, rgb, 6);
    }
    f.layout = std::make_shared<LasLayout>();
    f.layout->version_major = 1;
    f.layout->version_minor = 4;
    f.layout->point_format = 7;
    f.layout->scale = Eigen::Vector3d::Constant(0.001);
    f.layout->offset = Eigen::Vector3d(500000.0, 4000000.0, 0.0);
    MeshWriteOptions options;
    options.las = f.layout;
    saveMesh(f.las, f.cloud, options);
    if (pcl::PCDWriter().writeBinary(f.pcd, f.cloud.cloud) != 0)
      throw std::runtime_error("PCL could not write " + f.pcd);
    // The same points: both files read back to the same doubles.
    const MeshFile a = readMeshFile(f.las), b = readMeshFile(f.pcd);
    if (a.positions.cols() != static_cast<Eigen::Index>(f.points) || a.positions != b.positions ||
        !a.las || a.las->point_format != 7 || a.las->record_length != 36)
      throw std::runtime_error(
          "the LAS and PCD bench files differ: " + std::to_string(a.positions.cols()) + " and " +
          std::to_string(b.positions.cols()) + " points, max difference " +
          std::to_string(a.positions.cols() == b.positions.cols()
                             ? (a.positions - b.positions).cwiseAbs().maxCoeff()
                             : -1.0) +
          ", record length " + std::to_string(a.las ? a.las->record_length : 0));
    std::printf("LAS 1.4 format 7: %zu points, %.1f MB; binary PCD: %.1f MB\n", f.points,
                static_cast<double>(std::filesystem::file_size(f.las)) / 1e6,
                static_cast<double>(std::filesystem::file_size(f.pcd)) / 1e6);
    return f;
  }();
  return f;
}

void rates(benchmark::State& state, const std::string& file) {
  state.counters["MB/s"] =
      benchmark::Counter(static_cast<double>(std::filesystem::file_size(file)) / 1e6,
                         benchmark::Counter::kIsIterationInvariantRate);
  state.counters["Mpts/s"] = benchmark::Counter(static_cast<double>(lasFiles().points) / 1e6,
                                                benchmark::Counter::kIsIterationInvariantRate);
}

void readLas(benchmark::State& state, std::string LasFiles::*path) {
  const std::string& file = lasFiles().*path;
  for (auto _ : state) benchmark::DoNotOptimize(readMeshFile(file));
  rates(state, file);
}
BENCHMARK_CAPTURE(readLas, las, &LasFiles::las)
    ->Name("las/read")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();
BENCHMARK_CAPTURE(readLas, pcd, &LasFiles::pcd)
    ->Name("pcd_binary/read")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

void writeLas(benchmark::State& state) {
  const std::string out = files().dir + "/saved.las";
  MeshWriteOptions options;
  options.las = lasFiles().layout;
  for (auto _ : state) saveMesh(out, lasFiles().cloud, options);
  rates(state, out);
}
BENCHMARK(writeLas)
    ->Name("las/write")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

void writePcdBinary(benchmark::State& state) {
  const std::string out = files().dir + "/saved.pcd";
  for (auto _ : state) {
    if (pcl::PCDWriter().writeBinary(out, lasFiles().cloud.cloud) != 0)
      state.SkipWithError("PCL could not write the file");
  }
  rates(state, out);
}
BENCHMARK(writePcdBinary)
    ->Name("pcd_binary/write")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

const bool kLasRatios = [] {
  addRatio("las/read", "pcd_binary/read");
  addRatio("las/write", "pcd_binary/write");
  return true;
}();

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  const int status = pcl_ddg::bench::runWithRatios(argc, argv);
  std::filesystem::remove_all(pcl_ddg::bench::files().dir);
  return status;
}
