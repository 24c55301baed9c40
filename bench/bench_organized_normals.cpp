// PCA normals of organized 640 x 480 frames (the shared Kinect frame office1.pcd and the stereo
// frame table_scene_mug_stereo_textured.pcd), all in the same run with the same 2 threads and a
// 7 x 7 pixel neighbourhood (49 points):
//   ours/grid_pca                  computeOrganizedPCANormals (integral images, window radius 3)
//   baseline/grid_pca              pcl::IntegralImageNormalEstimation, COVARIANCE_MATRIX, size 7
//   baseline/average_3d_gradient   pcl::IntegralImageNormalEstimation, AVERAGE_3D_GRADIENT, size 7
//   baseline/organized_neighbor    pcl::NormalEstimationOMP, k = 49, pcl::search::OrganizedNeighbor
//   ours/kd_tree_pca               fitLocalSurfaces through our kd-tree, k = 49

#include <benchmark/benchmark.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/io/pcd_io.h>
#include <pcl/search/organized.h>

#include <array>
#include <stdexcept>
#include <string>

#include "bench_support.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/features/organized_normals.h"

namespace pcl_ddg {
namespace bench {
namespace {

pcl::PointCloud<pcl::PointXYZ>::ConstPtr loadFrame(const std::string& name) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  if (pcl::io::loadPCDFile(std::string(PCL_DDG_SHARED_DATA_DIR) + name, *cloud) != 0) {
    throw std::runtime_error("cannot read " + name);
  }
  return cloud;
}

const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& frame(std::int64_t which) {
  static const std::array<pcl::PointCloud<pcl::PointXYZ>::ConstPtr, 2> frames = {
      loadFrame("/clouds/office1.pcd"), loadFrame("/clouds/table_scene_mug_stereo_textured.pcd")};
  return frames.at(static_cast<std::size_t>(which));
}

void oursGrid(benchmark::State& state) {
  OrganizedNormalOptions options;
  options.window_radius = 3;
  options.threads = 2;
  for (auto _ : state) {
    OrganizedNormalResult result = computeOrganizedPCANormals(frame(state.range(0)), options);
    benchmark::DoNotOptimize(result.normals.data());
  }
}

void integralImage(
    benchmark::State& state,
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal>::NormalEstimationMethod method) {
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  estimation.setNormalEstimationMethod(method);
  estimation.setNormalSmoothingSize(7.0f);
  estimation.setDepthDependentSmoothing(false);
  estimation.setMaxDepthChangeFactor(0.02f);
  for (auto _ : state) {
    estimation.setInputCloud(frame(state.range(0)));
    pcl::PointCloud<pcl::Normal> normals;
    estimation.compute(normals);
    benchmark::DoNotOptimize(normals.data());
  }
}

void organizedNeighbor(benchmark::State& state) {
  for (auto _ : state) {
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimation(2);
    estimation.setInputCloud(frame(state.range(0)));
    estimation.setSearchMethod(std::make_shared<pcl::search::OrganizedNeighbor<pcl::PointXYZ>>());
    estimation.setKSearch(49);
    pcl::PointCloud<pcl::Normal> normals;
    estimation.compute(normals);
    benchmark::DoNotOptimize(normals.data());
  }
}

void oursKdTree(benchmark::State& state) {
  LocalFitOptions options;
  options.k = 49;
  options.threads = 2;
  for (auto _ : state) {
    LocalFitResult result = fitLocalSurfaces(frame(state.range(0)), nullptr, options);
    benchmark::DoNotOptimize(result.normals.data());
  }
}

BENCHMARK(oursGrid)
    ->Name("ours/grid_pca")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(integralImage, covariance,
                  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal>::COVARIANCE_MATRIX)
    ->Name("baseline/grid_pca")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(
    integralImage, gradient,
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal>::AVERAGE_3D_GRADIENT)
    ->Name("baseline/average_3d_gradient")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(organizedNeighbor)
    ->Name("baseline/organized_neighbor")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(oursKdTree)
    ->Name("ours/kd_tree_pca")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  using pcl_ddg::bench::addRatio;
  for (const char* frame : {"/0", "/1"}) {
    addRatio(std::string("ours/grid_pca") + frame,
             std::string("baseline/average_3d_gradient") + frame);
    addRatio(std::string("ours/grid_pca") + frame,
             std::string("baseline/organized_neighbor") + frame);
    addRatio(std::string("ours/grid_pca") + frame, std::string("ours/kd_tree_pca") + frame);
  }
  return pcl_ddg::bench::runWithRatios(argc, argv);
}
