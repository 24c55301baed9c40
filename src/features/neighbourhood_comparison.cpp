#include "pcl_ddg/features/neighbourhood_comparison.h"

#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <vector>

#include "pcl_ddg/interruption.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "pcl_ddg/search/mesh_ring_search.h"
#include "pcl_ddg/search/organized_grid_search.h"

namespace pcl_ddg {
namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;

Eigen::VectorXd jaccardOverlaps(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                                const std::shared_ptr<const MeshTopology>& topology,
                                const LocalFitOptions& options) {
  std::shared_ptr<MeshRingSearch<pcl::PointXYZ>> rings;
  std::shared_ptr<OrganizedGridSearch<pcl::PointXYZ>> grid;
  if (topology) {
    rings = std::make_shared<MeshRingSearch<pcl::PointXYZ>>(topology);
    rings->setInputCloud(cloud);
  } else {
    grid = std::make_shared<OrganizedGridSearch<pcl::PointXYZ>>(options.max_depth_jump);
    grid->setInputCloud(cloud);
  }
  // The neighbours the topological fit used: the grid's PCA averages a window.
  const bool grid_window = grid && options.method == LocalFitMethod::PCA && options.radius == 0.0;
  const pcl::search::Search<pcl::PointXYZ>& topological =
      rings ? static_cast<const pcl::search::Search<pcl::PointXYZ>&>(*rings) : *grid;
  KdTreeSearch<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  const auto n = static_cast<Eigen::Index>(cloud->size());
  Eigen::VectorXd overlap(n);
  detail::InterruptionPoll interruption;
#pragma omp parallel
  {
    pcl::Indices a, b, common;
    std::vector<float> distances;
#pragma omp for schedule(dynamic, 256)
    for (Eigen::Index i = 0; i < n; ++i) {
      if (interruption.stopped()) continue;
      const auto index = static_cast<pcl::index_t>(i);
      if (grid_window) {
        grid->windowSearch(index, gridWindowRadius(options.k), a, distances);
        tree.nearestKSearch(index, options.k, b, distances);
      } else if (options.radius > 0.0) {
        topological.radiusSearch(index, options.radius, a, distances);
        tree.radiusSearch(index, options.radius, b, distances);
      } else {
        topological.nearestKSearch(index, options.k, a, distances);
        tree.nearestKSearch(index, options.k, b, distances);
      }
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      common.clear();
      std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(common));
      const std::size_t united = a.size() + b.size() - common.size();
      overlap[i] =
          united > 0 ? static_cast<double>(common.size()) / static_cast<double>(united) : 0.0;
    }
  }
  interruption.throwIfStopped();
  return overlap;
}

}  // namespace

NeighbourhoodComparison compareNeighbourhoods(const LocalCloud& local,
                                              const std::shared_ptr<const MeshTopology>& topology,
                                              LocalFitOptions options) {
  const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud = local.points;
  if (!topology && !(cloud && cloud->height > 1)) {
    throw pcl::BadArgumentException(
        "comparing neighbourhoods needs a mesh (faces) or an organized cloud (a pixel grid)");
  }
  NeighbourhoodComparison c;
  options.neighbourhood = topology ? NeighbourhoodKind::MeshRings : NeighbourhoodKind::Grid;
  c.topological = fitLocalSurfaces(local, topology, options);
  options.neighbourhood = NeighbourhoodKind::KdTree;
  c.kd_tree = fitLocalSurfaces(local, topology, options);

  const auto n = static_cast<Eigen::Index>(cloud->size());
  c.angle_difference.resize(n);
  std::vector<double> compared;
  compared.reserve(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d a = c.topological.normals[i].getNormalVector3fMap().cast<double>();
    const Eigen::Vector3d b = c.kd_tree.normals[i].getNormalVector3fMap().cast<double>();
    if (!a.allFinite() || !b.allFinite()) {
      c.angle_difference[i] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    c.angle_difference[i] = std::atan2(a.cross(b).norm(), a.dot(b)) * kDegrees;
    compared.push_back(c.angle_difference[i]);
  }
  c.overlap = jaccardOverlaps(cloud, topology, options);

  NeighbourhoodComparison::Summary& s = c.summary;
  s.compared = static_cast<std::int64_t>(compared.size());
  s.mean_overlap = n > 0 ? c.overlap.mean() : 0.0;
  if (compared.empty()) return c;
  std::sort(compared.begin(), compared.end());
  auto quantile = [&](double q) {
    return compared[static_cast<std::size_t>(q * (compared.size() - 1) + 0.5)];
  };
  double sum = 0.0;
  for (const double d : compared) {
    sum += d;
    s.share_over_5 += d > 5.0;
    s.share_over_30 += d > 30.0;
  }
  s.mean = sum / compared.size();
  s.median = quantile(0.5);
  s.percentile95 = quantile(0.95);
  s.max = compared.back();
  s.share_over_5 /= compared.size();
  s.share_over_30 /= compared.size();
  return c;
}

}  // namespace pcl_ddg
