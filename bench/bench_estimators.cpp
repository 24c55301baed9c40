// PCA and quadric normals, k = 16, on a 1.15M-point torus: with mesh-ring (BFS) and kd-tree
// (KdTreeSearch) neighbourhoods, next to pcl::NormalEstimationOMP with pcl::search::KdTree and the
// same thread count. Search structures are built once, outside the timings.
#include <benchmark/benchmark.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/search/kdtree.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "bench_support.h"
#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/features/quadric_normal_estimation.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "pcl_ddg/search/mesh_ring_search.h"

namespace pcl_ddg {
namespace bench {
namespace {

constexpr int kAround = 1536, kTube = 750;  // 1,152,000 points
constexpr int kNeighbours = 16;

int threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// The cloud, and both search structures built once (every estimator reuses them, as a pipeline
// computing several features would).
struct Fixture {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  std::shared_ptr<MeshRingSearch<pcl::PointXYZ>> rings;
  std::shared_ptr<KdTreeSearch<pcl::PointXYZ>> tree =
      std::make_shared<KdTreeSearch<pcl::PointXYZ>>();
  std::shared_ptr<pcl::search::KdTree<pcl::PointXYZ>> pcl_tree =
      std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();

  Fixture() {
    const BenchMesh& mesh = torusMesh(kAround, kTube);
    cloud->resize(mesh.points.cols());
    for (Eigen::Index i = 0; i < mesh.points.cols(); ++i) {
      (*cloud)[i].getVector3fMap() = mesh.points.col(i).cast<float>();
    }
    rings = std::make_shared<MeshRingSearch<pcl::PointXYZ>>(
        std::make_shared<const MeshTopology>(static_cast<int>(mesh.points.cols()), mesh.triangles));
    rings->setInputCloud(cloud);
    tree->setInputCloud(cloud);
    pcl_tree->setInputCloud(cloud);
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

template <typename Estimator>
void configure(Estimator& estimator, pcl::search::Search<pcl::PointXYZ>::Ptr search) {
  estimator.setInputCloud(fixture().cloud);
  estimator.setSearchMethod(search);
  estimator.setKSearch(kNeighbours);
}

void setCounters(benchmark::State& state) {
  state.counters["points"] = static_cast<double>(fixture().cloud->size());
  state.counters["threads"] = threads();
}

void pca(benchmark::State& state, bool mesh_rings) {
  PCANormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
  configure(estimator, mesh_rings ? pcl::search::Search<pcl::PointXYZ>::Ptr(fixture().rings)
                                  : pcl::search::Search<pcl::PointXYZ>::Ptr(fixture().tree));
  estimator.setNumberOfThreads(threads());
  pcl::PointCloud<pcl::Normal> normals;
  for (auto _ : state) {
    estimator.compute(normals);
    benchmark::DoNotOptimize(normals.data());
  }
  setCounters(state);
}
BENCHMARK_CAPTURE(pca, bfs, true)
    ->Name("ours/pca_bfs")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(pca, kdtree, false)
    ->Name("ours/pca_kdtree")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void quadric(benchmark::State& state) {
  QuadricNormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
  configure(estimator, fixture().rings);
  estimator.setNumberOfThreads(threads());
  pcl::PointCloud<pcl::Normal> normals;
  pcl::PointCloud<pcl::PrincipalCurvatures> curvatures;
  for (auto _ : state) {
    estimator.computeWithCurvatures(normals, curvatures);
    benchmark::DoNotOptimize(curvatures.data());
  }
  setCounters(state);
}
BENCHMARK(quadric)
    ->Name("ours/quadric_bfs+curvatures")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void pclNormalEstimationOMP(benchmark::State& state) {
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimator(threads());
  configure(estimator, fixture().pcl_tree);
  pcl::PointCloud<pcl::Normal> normals;
  for (auto _ : state) {
    estimator.compute(normals);
    benchmark::DoNotOptimize(normals.data());
  }
  setCounters(state);
}
BENCHMARK(pclNormalEstimationOMP)
    ->Name("baseline/pcl_normal_estimation_omp")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  using pcl_ddg::bench::addRatio;
  addRatio("ours/pca_bfs", "baseline/pcl_normal_estimation_omp");
  addRatio("ours/pca_kdtree", "baseline/pcl_normal_estimation_omp");
  addRatio("ours/quadric_bfs+curvatures", "ours/pca_bfs");
  return pcl_ddg::bench::runWithRatios(argc, argv);
}
