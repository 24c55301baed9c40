// How the pipeline scales, from about 1M to 20M triangles and from 1M to 50M points: time per
// element should stay flat, and memory per vertex small. Each measurement runs in a fresh process
// (this program, started again with --pipeline), so that its peak resident memory (VmHWM) is
// its own; the inputs are binary PLY files made first into a temporary folder:
//   meshes  Loop subdivision of shared meshes (igea once and twice, bumpy six times, rocker-arm
//           five times): load -> MeshTopology -> area normals -> all curvatures
//   clouds  points sampled on igea.ply's surface: load -> PCA normals through the kd-tree, k = 16
// Reported per size: ns per element for each phase and in all, peak bytes per vertex (above the
// process's own footprint before loading), and the ratio of the largest size's time per element
// to the smallest's: medians with --benchmark_repetitions=N, which a shared VM needs (single runs
// of the 1M mesh took 299 and 447 ns per triangle). With --write-cloud=COUNT:PATH it only writes
// such a cloud (for bench_out_of_core.sh), with --write-mesh=SHARED_MESH:LEVELS:PATH such a mesh.
#include <benchmark/benchmark.h>
#include <pcl/conversions.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <vector>

#include "bench_support.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/surface/mesh_normals.h"

namespace pcl_ddg {
namespace bench {
namespace {

std::string sharedMesh(const std::string& name) {
  return std::string(PCL_DDG_SHARED_DATA_DIR) + "/meshes/" + name;
}

// One level of Loop subdivision of a closed manifold triangle mesh (Loop 1987, Warren's weights).
void loopSubdivide(Eigen::Matrix3Xd& points, Eigen::Matrix3Xi& triangles) {
  const MeshTopology topology(static_cast<int>(points.cols()), triangles);
  const int n = topology.numVertices(), edges = topology.numEdges();
  Eigen::Matrix3Xd next(3, n + edges);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < n; ++v) {
    const IndexSpan ring = topology.neighbours(v);
    const int valence = ring.size();
    if (valence < 3) {
      next.col(v) = points.col(v);
      continue;
    }
    const double beta = valence == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * valence);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int w : ring) sum += points.col(w);
    next.col(v) = (1.0 - valence * beta) * points.col(v) + beta * sum;
  }
  // Edge points: 3/8 of the ends and 1/8 of the two opposite corners.
  Eigen::Matrix3Xd opposite = Eigen::Matrix3Xd::Zero(3, edges);
  for (int t = 0; t < topology.numTriangles(); ++t) {
    for (int k = 0; k < 3; ++k)
      opposite.col(topology.triangleEdges()(k, t)) += points.col(triangles(k, t));
  }
  for (int e = 0; e < edges; ++e) {
    const auto& ends = topology.edgeVertices().col(e);
    next.col(n + e) = 0.375 * (points.col(ends[0]) + points.col(ends[1])) + 0.125 * opposite.col(e);
  }
  Eigen::Matrix3Xi finer(3, 4 * triangles.cols());
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    // triangleEdges()(k, t) is the side opposite corner k.
    const int a = triangles(0, t), b = triangles(1, t), c = triangles(2, t);
    const int ab = n + topology.triangleEdges()(2, t), bc = n + topology.triangleEdges()(0, t),
              ca = n + topology.triangleEdges()(1, t);
    finer.col(4 * t) << a, ab, ca;
    finer.col(4 * t + 1) << ab, b, bc;
    finer.col(4 * t + 2) << ca, bc, c;
    finer.col(4 * t + 3) << ab, bc, ca;
  }
  points.swap(next);
  triangles.swap(finer);
}

struct Input {
  std::string label;
  std::string path;
  std::int64_t elements = 0;  // triangles, or points
  bool cloud = false;
};

std::vector<Input>& inputs() {
  static std::vector<Input> list;
  return list;
}

void writeMesh(const std::string& path, const Eigen::Matrix3Xd& points,
               const Eigen::Matrix3Xi& triangles) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << points.cols()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << triangles.cols()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f p = points.col(i).cast<float>();
    out.write(reinterpret_cast<const char*>(p.data()), 12);
  }
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    out.put(3);
    out.write(reinterpret_cast<const char*>(triangles.col(t).data()), 12);
  }
}

struct SubdividedMesh {
  Eigen::Matrix3Xd points;
  Eigen::Matrix3Xi triangles;
};

/** A shared mesh after `levels` Loop subdivisions. */
SubdividedMesh subdividedMesh(const std::string& name, int levels) {
  const MeshFile file = readMeshFile(sharedMesh(name));
  SubdividedMesh mesh{file.positions, MeshTopology(file.mesh).triangles()};
  for (int l = 0; l < levels; ++l) loopSubdivide(mesh.points, mesh.triangles);
  return mesh;
}

// A binary PLY cloud of `count` points on igea's surface, area-weighted, in triangle order.
void writeSampledCloud(const std::string& path, std::int64_t count) {
  const MeshFile igea = readMeshFile(sharedMesh("igea.ply"));
  const MeshTopology topology(igea.mesh);
  const Eigen::Matrix3Xi& t = topology.triangles();
  std::vector<double> area(t.cols());
  for (Eigen::Index i = 0; i < t.cols(); ++i) {
    const Eigen::Vector3d a = igea.positions.col(t(0, i));
    area[i] = (igea.positions.col(t(1, i)) - a).cross(igea.positions.col(t(2, i)) - a).norm();
  }
  std::mt19937_64 random(count);
  std::discrete_distribution<Eigen::Index> triangle(area.begin(), area.end());
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Index> picked(static_cast<std::size_t>(count));
  for (auto& p : picked) p = triangle(random);
  std::sort(picked.begin(), picked.end());
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << count
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const Eigen::Index i : picked) {
    double u = unit(random), v = unit(random);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const Eigen::Vector3d a = igea.positions.col(t(0, i));
    const Eigen::Vector3f p =
        (a + u * (igea.positions.col(t(1, i)) - a) + v * (igea.positions.col(t(2, i)) - a))
            .cast<float>();
    out.write(reinterpret_cast<const char*>(p.data()), 12);
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

void makeInputs(const std::string& folder) {
  const std::pair<const char*, int> meshes[] = {
      {"igea.ply", 1}, {"igea.ply", 2}, {"bumpy.off", 6}, {"rocker-arm.off", 5}};
  for (const auto& [name, levels] : meshes) {
    const SubdividedMesh mesh = subdividedMesh(name, levels);
    std::ostringstream label;
    label << "mesh/" << (mesh.triangles.cols() + 500000) / 1000000 << "M";
    const std::string path = folder + "/" + label.str().substr(5) + "_triangles.ply";
    writeMesh(path, mesh.points, mesh.triangles);
    inputs().push_back({label.str(), path, mesh.triangles.cols(), false});
  }
  for (const std::int64_t count : {1000000LL, 10000000LL, 50000000LL}) {
    const std::string path = folder + "/" + std::to_string(count / 1000000) + "M_points.ply";
    writeSampledCloud(path, count);
    inputs().push_back({"cloud/" + std::to_string(count / 1000000) + "M", path, count, true});
  }
}

/** This process's peak resident memory so far: the largest VmHWM read, the peak of its own
 *  address space. getrusage's ru_maxrss would not do: Linux carries it over an exec, so the child
 *  started by fork and exec would begin at the parent's size. The kernel brings VmHWM up to date
 *  lazily (when memory is unmapped), so a later reading can be lower than an earlier one. */
long long peakResidentBytes() {
  static long long peak = 0;
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) {
      peak = std::max(peak, std::stoll(line.substr(6)) * 1024);  // in kB
      return peak;
    }
  }
  throw std::runtime_error("no VmHWM in /proc/self/status");
}

// The child: runs the pipeline on one file and prints "phase seconds" lines and the peak memory.
int runPipeline(const std::string& path, bool cloud) {
  const auto clock = [] { return std::chrono::steady_clock::now(); };
  const auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  const long long base = peakResidentBytes();
  auto t0 = clock();
  MeshFile file = readMeshFile(path);
  auto t1 = clock();
  std::printf("load %.6f\npeak_after_load %lld\n", seconds(t0, t1), peakResidentBytes());
  if (cloud) {
    auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    pcl::fromPCLPointCloud2(file.mesh.cloud, *points);
    file.mesh.cloud = pcl::PCLPointCloud2();  // the tools keep only what they write back
    t0 = clock();
    LocalFitOptions options;
    options.k = 16;
    const LocalFitResult fit = fitLocalSurfaces(points, nullptr, options);
    benchmark::DoNotOptimize(fit.normals.data());
    std::printf("normals %.6f\n", seconds(t0, clock()));
  } else {
    t0 = clock();
    const MeshTopology topology(file.mesh);
    t1 = clock();
    std::printf("topology %.6f\npeak_after_topology %lld\n", seconds(t0, t1), peakResidentBytes());
    const MeshNormals normals = computeMeshNormals(topology, file.positions);
    benchmark::DoNotOptimize(normals.normals.data());
    const auto t2 = clock();
    std::printf("normals %.6f\npeak_after_normals %lld\n", seconds(t1, t2), peakResidentBytes());
    const VertexCurvatures curvatures = computeCurvatures(topology, file.positions);
    benchmark::DoNotOptimize(curvatures.k1.data());
    std::printf("curvature %.6f\n", seconds(t2, clock()));
  }
  std::printf("vertices %lld\npeak_bytes %lld\nbase_bytes %lld\n",
              static_cast<long long>(file.positions.cols()), peakResidentBytes(), base);
  return 0;
}

// Runs this program again on one input and reads back what it printed.
std::map<std::string, double> measure(const Input& input) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t child = fork();
  if (child == 0) {
    dup2(fds[1], STDOUT_FILENO);
    close(fds[0]);
    const std::string flag =
        std::string("--pipeline=") + (input.cloud ? "cloud:" : "mesh:") + input.path;
    execl("/proc/self/exe", "bench_scale", flag.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof(buffer))) > 0;) text.append(buffer, n);
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("the pipeline failed on " + input.path);
  std::map<std::string, double> values;
  std::istringstream lines(text);
  for (std::string key; lines >> key;) lines >> values[key];
  return values;
}

// Every run's time per element, by input, for the flatness line printed at the end.
std::map<const Input*, std::vector<double>>& nsPerElement() {
  static std::map<const Input*, std::vector<double>> runs;
  return runs;
}

void scale(benchmark::State& state, const Input* input) {
  for (auto _ : state) {
    const std::map<std::string, double> v = measure(*input);
    double total = 0.0;
    for (const char* phase : {"load", "topology", "normals", "curvature"}) {
      if (!v.count(phase)) continue;
      total += v.at(phase);
      state.counters[std::string("ns_per_element_") + phase] = 1e9 * v.at(phase) / input->elements;
    }
    state.SetIterationTime(total);
    state.counters["ns_per_element"] = 1e9 * total / input->elements;
    nsPerElement()[input].push_back(1e9 * total / input->elements);
    state.counters["bytes_per_vertex"] =
        (v.at("peak_bytes") - v.at("base_bytes")) / v.at("vertices");
    state.counters["elements"] = static_cast<double>(input->elements);
  }
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// The largest input's time per element over the smallest's, for meshes and for clouds (medians
// of the runs, one per --benchmark_repetitions).
void printFlatness() {
  for (const bool cloud : {false, true}) {
    const Input *smallest = nullptr, *largest = nullptr;
    for (const auto& [input, runs] : nsPerElement()) {
      if (input->cloud != cloud || runs.empty()) continue;
      if (!smallest || input->elements < smallest->elements) smallest = input;
      if (!largest || input->elements > largest->elements) largest = input;
    }
    if (!smallest || smallest == largest) continue;
    const double small = median(nsPerElement()[smallest]), large = median(nsPerElement()[largest]);
    std::printf("%s: %s %.0f ns per element, %s %.0f: %.2fx (median of %zu and %zu runs)\n",
                cloud ? "clouds" : "meshes", smallest->label.c_str(), small, largest->label.c_str(),
                large, large / small, nsPerElement()[smallest].size(),
                nsPerElement()[largest].size());
  }
}

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  using namespace pcl_ddg::bench;
  if (argc == 2 && std::string(argv[1]).rfind("--write-cloud=", 0) == 0) {
    // For bench_out_of_core.sh: --write-cloud=COUNT:PATH
    const std::string spec = std::string(argv[1]).substr(14);
    writeSampledCloud(spec.substr(spec.find(':') + 1), std::stoll(spec.substr(0, spec.find(':'))));
    return 0;
  }
  if (argc == 2 && std::string(argv[1]).rfind("--write-mesh=", 0) == 0) {
    // One of the scale meshes on its own: --write-mesh=SHARED_MESH:LEVELS:PATH
    const std::string spec = std::string(argv[1]).substr(13);
    const std::size_t first = spec.find(':'), second = spec.find(':', first + 1);
    const SubdividedMesh mesh = subdividedMesh(
        spec.substr(0, first), std::stoi(spec.substr(first + 1, second - first - 1)));
    writeMesh(spec.substr(second + 1), mesh.points, mesh.triangles);
    return 0;
  }
  if (argc == 2 && std::string(argv[1]).rfind("--pipeline=", 0) == 0) {
    const std::string spec = std::string(argv[1]).substr(11);
    return runPipeline(spec.substr(spec.find(':') + 1), spec.rfind("cloud:", 0) == 0);
  }
  const std::string folder =
      (std::filesystem::temp_directory_path() / "pcl_ddg_bench_scale").string();
  std::filesystem::create_directories(folder);
  makeInputs(folder);
  // The inputs' pages are written back to disk now rather than during the first measurements
  // (that doubled the load time of the first meshes).
  sync();
  for (const Input& input : inputs()) {
    benchmark::RegisterBenchmark(input.label.c_str(), scale, &input)
        ->Unit(benchmark::kMillisecond)
        ->UseManualTime()
        ->Iterations(1);
  }
  const int result = runWithRatios(argc, argv);
  printFlatness();
  std::filesystem::remove_all(folder);
  return result;
}
