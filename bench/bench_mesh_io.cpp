// Loading and saving the 1.15M-vertex bench torus, as the tools do, against PCL's own readers and
// writer in the same run:
//   load_ascii_off   readMeshFile on an ascii OFF (%.9g)    vs a textbook iostream >> loader
//   load_binary_ply  readMeshFile on a binary PLY            vs pcl::io::loadPLYFile
//   load_ascii_ply   readMeshFile on an ascii PLY            vs pcl::io::loadPLYFile
//   save_binary_ply  saveMesh                                vs pcl::io::savePLYFileBinary
// The files are written once into a temporary folder.
#include <benchmark/benchmark.h>
#include <pcl/conversions.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "bench_support.h"
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

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  const int status = pcl_ddg::bench::runWithRatios(argc, argv);
  std::filesystem::remove_all(pcl_ddg::bench::files().dir);
  return status;
}
