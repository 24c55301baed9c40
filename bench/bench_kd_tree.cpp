// The kd-tree under KdTreeSearch (nanoflann's, reading the points where they lie) against PCL's
// pcl::search::KdTree (FLANN's, searching its own reordered copy): the build, its heap per point,
// and the 16 nearest of every point, one thread, through pcl::search::Search for both. On the
// bench torus's 1,152,000 points in grid order (a scan's acquisition order: neighbours near in
// memory) and shuffled (the worst order for reading the points in place).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <memory>
#include <random>

#include "bench_support.h"
#include "pcl_ddg/search/kd_tree_search.h"

namespace pcl_ddg {
namespace bench {
namespace {

constexpr int kAround = 1536, kTube = 750;  // 1,152,000 points
constexpr int kNeighbours = 16;

pcl::PointCloud<pcl::PointXYZ>::ConstPtr torus(bool shuffled) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  const BenchMesh& mesh = torusMesh(kAround, kTube);
  cloud->resize(mesh.points.cols());
  for (Eigen::Index i = 0; i < mesh.points.cols(); ++i)
    (*cloud)[i].getVector3fMap() = mesh.points.col(i).cast<float>();
  if (shuffled) std::shuffle(cloud->begin(), cloud->end(), std::mt19937(7));
  return cloud;
}

const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud(bool shuffled) {
  static const pcl::PointCloud<pcl::PointXYZ>::ConstPtr clouds[2] = {torus(false), torus(true)};
  return clouds[shuffled];
}

std::size_t heapInUse() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

template <class Tree>
void build(benchmark::State& state) {
  const bool shuffled = state.range(0) != 0;
  state.SetLabel(shuffled ? "shuffled" : "grid order");
  const auto& points = cloud(shuffled);
  double bytes = 0.0;
  for (auto _ : state) {
    const std::size_t before = heapInUse();
    Tree tree;
    tree.setInputCloud(points);
    bytes = static_cast<double>(heapInUse() - before) / static_cast<double>(points->size());
    benchmark::DoNotOptimize(tree);
  }
  state.counters["heap_bytes_per_point"] = bytes;
}

template <class Tree>
void query(benchmark::State& state) {
  const bool shuffled = state.range(0) != 0;
  state.SetLabel(shuffled ? "shuffled" : "grid order");
  const auto& points = cloud(shuffled);
  Tree tree;
  tree.setInputCloud(points);
  pcl::Indices found;
  std::vector<float> distances;
  for (auto _ : state) {
    double sum = 0.0;
    for (std::size_t i = 0; i < points->size(); ++i) {
      tree.nearestKSearch((*points)[i], kNeighbours, found, distances);
      sum += distances.back();
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points->size()));
}

using Ours = KdTreeSearch<pcl::PointXYZ>;
using Pcl = pcl::search::KdTree<pcl::PointXYZ>;

BENCHMARK_TEMPLATE(build, Ours)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(build, Pcl)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(query, Ours)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(query, Pcl)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

BENCHMARK_MAIN();
