// MeshTopology + MeshReport on 1.15M-vertex meshes, as a tool builds them from a loaded
// pcl::PolygonMesh, against building libigl-style edge adjacency (all 3F half-edges keyed by their
// sorted end points and sorted, as igl::unique_edge_map does) in the same run.
//   regular  the bench torus, vertices in grid order
//   shuffled the same torus with its vertices and faces in random order (scan-like)
//   strip    one long strip of triangles (a chain for a union-find without path compression)
#include <benchmark/benchmark.h>
#include <pcl/Vertices.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "bench_support.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace bench {
namespace {

struct PolygonInput {
  int num_vertices = 0;
  std::vector<pcl::Vertices> polygons;
  Eigen::Matrix3Xd points;
};

PolygonInput fromTriangles(const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xi& triangles) {
  PolygonInput in;
  in.num_vertices = static_cast<int>(points.cols());
  in.points = points;
  in.polygons.resize(triangles.cols());
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    in.polygons[t].vertices = {triangles(0, t), triangles(1, t), triangles(2, t)};
  }
  return in;
}

const PolygonInput& regular() {
  static const PolygonInput in = [] {
    const BenchMesh& mesh = torusMesh(1600, 720);
    return fromTriangles(mesh.points, mesh.triangles);
  }();
  return in;
}

const PolygonInput& shuffled() {
  static const PolygonInput in = [] {
    const BenchMesh& mesh = torusMesh(1600, 720);
    std::mt19937 random(7);
    std::vector<int> vertex_order(mesh.points.cols()), face_order(mesh.triangles.cols());
    std::iota(vertex_order.begin(), vertex_order.end(), 0);
    std::iota(face_order.begin(), face_order.end(), 0);
    std::shuffle(vertex_order.begin(), vertex_order.end(), random);
    std::shuffle(face_order.begin(), face_order.end(), random);
    Eigen::Matrix3Xd points(3, mesh.points.cols());
    for (Eigen::Index v = 0; v < points.cols(); ++v)
      points.col(vertex_order[v]) = mesh.points.col(v);
    Eigen::Matrix3Xi triangles(3, mesh.triangles.cols());
    for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
      for (int k = 0; k < 3; ++k) triangles(k, face_order[t]) = vertex_order[mesh.triangles(k, t)];
    }
    return fromTriangles(points, triangles);
  }();
  return in;
}

// 1,000,000 triangles in one strip: vertices 0..n+1 zig-zag along x.
const PolygonInput& strip() {
  static const PolygonInput in = [] {
    const int triangles = 1000000;
    Eigen::Matrix3Xd points(3, triangles + 2);
    for (int v = 0; v < triangles + 2; ++v) points.col(v) << 0.5 * v, v % 2, 0.0;
    Eigen::Matrix3Xi faces(3, triangles);
    for (int t = 0; t < triangles; ++t) {
      if (t % 2 == 0) {
        faces.col(t) << t, t + 1, t + 2;
      } else {
        faces.col(t) << t + 1, t, t + 2;
      }
    }
    return fromTriangles(points, faces);
  }();
  return in;
}

void topologyAndReport(benchmark::State& state, const PolygonInput& (*input)()) {
  const PolygonInput& in = input();
  for (auto _ : state) {
    const MeshTopology topology(in.num_vertices, in.polygons);
    benchmark::DoNotOptimize(makeMeshReport(topology, in.points));
  }
}
BENCHMARK_CAPTURE(topologyAndReport, regular, regular)
    ->Name("ours/topology_regular")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(topologyAndReport, shuffled, shuffled)
    ->Name("ours/topology_shuffled")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(topologyAndReport, strip, strip)
    ->Name("ours/topology_strip")
    ->Unit(benchmark::kMillisecond);

// libigl-style: every half-edge as (sorted end points, triangle), sorted; unique edges, and the
// triangles per edge (boundary and non-manifold counts) from the runs of equal keys.
void edgeSortBaseline(benchmark::State& state, const PolygonInput& (*input)()) {
  const PolygonInput& in = input();
  for (auto _ : state) {
    std::vector<std::uint64_t> keys;
    keys.reserve(3 * in.polygons.size());
    for (const pcl::Vertices& p : in.polygons) {
      for (int k = 0; k < 3; ++k) {
        const std::uint64_t a = static_cast<std::uint32_t>(p.vertices[k]);
        const std::uint64_t b = static_cast<std::uint32_t>(p.vertices[(k + 1) % 3]);
        keys.push_back(std::min(a, b) << 32 | std::max(a, b));
      }
    }
    std::sort(keys.begin(), keys.end());
    std::int64_t edges = 0, boundary = 0, nonmanifold = 0;
    for (std::size_t i = 0; i < keys.size();) {
      std::size_t j = i;
      while (j < keys.size() && keys[j] == keys[i]) ++j;
      ++edges;
      boundary += j - i == 1;
      nonmanifold += j - i > 2;
      i = j;
    }
    benchmark::DoNotOptimize(edges + boundary + nonmanifold);
  }
}
BENCHMARK_CAPTURE(edgeSortBaseline, regular, regular)
    ->Name("baseline/topology_regular")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(edgeSortBaseline, shuffled, shuffled)
    ->Name("baseline/topology_shuffled")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(edgeSortBaseline, strip, strip)
    ->Name("baseline/topology_strip")
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  return pcl_ddg::bench::runWithRatios(argc, argv);
}
