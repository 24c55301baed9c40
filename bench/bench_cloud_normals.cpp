// PCA normals of clouds through the kd-tree path, against Open3D's EstimateNormals (Debian's
// libopen3d-dev) in the same run, k = 16, 2 threads, the kd-tree built inside every iteration
// (as EstimateNormals does):
//   rs1       ../shared/data/clouds/rs1.pcd, 289,541 points of a range scan
//   scan10M   10,000,000 points sampled from igea.ply's surface (area-weighted, triangle order)
//   shuffled  the same 10M points in random order (merged or re-exported scans)
#include <benchmark/benchmark.h>
#include <omp.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <pcl/conversions.h>

#include <algorithm>
#include <map>
#include <random>

#include "bench_support.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace bench {
namespace {

constexpr int kNeighbours = 16;

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr sampledScan(bool shuffled) {
  const MeshFile igea = readMeshFile(std::string(PCL_DDG_SHARED_DATA_DIR) + "/meshes/igea.ply");
  const MeshTopology topology(igea.mesh);
  const Eigen::Matrix3Xi& t = topology.triangles();
  std::vector<double> area(t.cols());
  for (Eigen::Index i = 0; i < t.cols(); ++i) {
    const Eigen::Vector3d a = igea.positions.col(t(0, i));
    area[i] = 0.5 * (igea.positions.col(t(1, i)) - a).cross(igea.positions.col(t(2, i)) - a).norm();
  }
  std::mt19937_64 random(11);
  std::discrete_distribution<Eigen::Index> triangle(area.begin(), area.end());
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Index> picked(10000000);
  for (auto& p : picked) p = triangle(random);
  std::sort(picked.begin(), picked.end());  // triangle order, as a mesh-derived scan is stored
  auto cloud = std::make_shared<Cloud>();
  cloud->reserve(picked.size());
  for (const Eigen::Index i : picked) {
    double u = unit(random), v = unit(random);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const Eigen::Vector3d a = igea.positions.col(t(0, i));
    const Eigen::Vector3d p =
        a + u * (igea.positions.col(t(1, i)) - a) + v * (igea.positions.col(t(2, i)) - a);
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  }
  if (shuffled) std::shuffle(cloud->begin(), cloud->end(), std::mt19937(3));
  return cloud;
}

const Cloud::Ptr& cloudNamed(const std::string& name) {
  static std::map<std::string, Cloud::Ptr> clouds;
  Cloud::Ptr& cloud = clouds[name];
  if (cloud) return cloud;
  if (name == "rs1") {
    cloud = std::make_shared<Cloud>();
    pcl::fromPCLPointCloud2(
        loadMesh(std::string(PCL_DDG_SHARED_DATA_DIR) + "/clouds/rs1.pcd").cloud, *cloud);
  } else {
    cloud = sampledScan(name == "shuffled");
  }
  return cloud;
}

void ours(benchmark::State& state, const std::string& name) {
  const Cloud::Ptr& cloud = cloudNamed(name);
  LocalFitOptions options;
  options.k = kNeighbours;
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(fitLocalSurfaces(cloud, nullptr, options));
  state.counters["points"] = static_cast<double>(cloud->size());
}

void open3dEstimateNormals(benchmark::State& state, const std::string& name) {
  const Cloud::Ptr& cloud = cloudNamed(name);
  open3d::geometry::PointCloud points;
  points.points_.reserve(cloud->size());
  for (const auto& p : *cloud) points.points_.emplace_back(p.x, p.y, p.z);
  omp_set_num_threads(2);
  for (auto _ : state) {
    points.normals_.clear();  // else EstimateNormals orients towards the normals it finds
    points.EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(kNeighbours));
    benchmark::DoNotOptimize(points.normals_.data());
  }
  state.counters["points"] = static_cast<double>(cloud->size());
}

}  // namespace
}  // namespace bench
}  // namespace pcl_ddg

int main(int argc, char** argv) {
  using namespace pcl_ddg::bench;
  for (const char* name : {"rs1", "scan10M", "shuffled"}) {
    benchmark::RegisterBenchmark((std::string("ours/") + name).c_str(), ours, name)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime();
    benchmark::RegisterBenchmark((std::string("baseline/") + name).c_str(), open3dEstimateNormals, name)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime();
  }
  return runWithRatios(argc, argv);
}
