// Orientation by propagation along a minimum spanning tree, on 1M points of a torus (the bench
// torus's vertices) with PCA normals (k = 16) whose signs were scrambled: ours
// (orientNormalsConsistently, the 10-nearest graph) against Open3D 0.16's
// OrientNormalsConsistentTangentPlane(10) in the same run, 2 threads each. Both start from the
// same scrambled normals every iteration.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <open3d/geometry/PointCloud.h>

#include <random>

#include "bench_support.h"
#include "pcl_ddg/features/consistent_orientation.h"
#include "pcl_ddg/features/local_fit.h"

namespace pcl_ddg {
namespace bench {
namespace {

constexpr int kGraphNeighbours = 10;

struct Scrambled {
  pcl::PointCloud<pcl::PointXYZ>::Ptr points{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::PointCloud<pcl::Normal> normals;
};

const Scrambled& scrambled() {
  static const Scrambled s = [] {
    Scrambled s;
    const BenchMesh& torus = torusMesh(1400, 720);  // 1,008,000 points
    for (Eigen::Index v = 0; v < torus.points.cols(); ++v) {
      const Eigen::Vector3f p = torus.points.col(v).cast<float>();
      s.points->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    }
    LocalFitOptions options;
    options.threads = 2;
    s.normals = fitLocalSurfaces(s.points, nullptr, options).normals;
    std::mt19937 random(1);
    for (auto& n : s.normals) {
      if (random() % 2 != 0) n.getNormalVector3fMap() *= -1.0f;
    }
    return s;
  }();
  return s;
}

void ours(benchmark::State& state) {
  const Scrambled& s = scrambled();
  ConsistentOrientationOptions options;
  options.k = kGraphNeighbours;
  options.threads = 2;
  for (auto _ : state) {
    state.PauseTiming();
    pcl::PointCloud<pcl::Normal> normals = s.normals;
    state.ResumeTiming();
    benchmark::DoNotOptimize(orientNormalsConsistently(*s.points, normals, options));
  }
  state.counters["points"] = static_cast<double>(s.points->size());
}

void open3dTangentPlane(benchmark::State& state) {
  const Scrambled& s = scrambled();
  open3d::geometry::PointCloud cloud;
  for (const auto& p : *s.points) cloud.points_.emplace_back(p.x, p.y, p.z);
  omp_set_num_threads(2);
  for (auto _ : state) {
    state.PauseTiming();
    cloud.normals_.clear();
    for (const auto& n : s.normals) cloud.normals_.emplace_back(n.normal_x, n.normal_y, n.normal_z);
    state.ResumeTiming();
    cloud.OrientNormalsConsistentTangentPlane(kGraphNeighbours);
    benchmark::DoNotOptimize(cloud.normals_.data());
  }
}

BENCHMARK(ours)->Name("ours/mst_orientation_1M")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(open3dTangentPlane)
    ->Name("baseline/mst_orientation_1M")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  return pcl_ddg::bench::runWithRatios(argc, argv);
}
