#include "pcl_ddg/features/local_fit.h"

#include <pcl/exceptions.h>

#include <numeric>

#include "pcl_ddg/features/organized_normals.h"
#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/features/quadric_normal_estimation.h"
#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "pcl_ddg/search/mesh_ring_search.h"
#include "pcl_ddg/search/organized_grid_search.h"

namespace pcl_ddg {
namespace {

constexpr int kSpanningTreeNeighbours = 10;

// The viewpoint in the cloud's local frame (unset: the world's origin, as PCL's default).
Eigen::Vector3d localViewpoint(const LocalCloud& cloud, const LocalFitOptions& options) {
  return options.viewpoint.value_or(Eigen::Vector3d::Zero()) - cloud.origin;
}

template <typename Estimator>
void configure(Estimator& estimator, const LocalCloud& cloud,
               const std::shared_ptr<const MeshTopology>& topology, const LocalFitOptions& options,
               const pcl::IndicesPtr& indices) {
  estimator.setInputCloud(cloud.points);
  estimator.setInputPositions(cloud.positions);
  if (indices) estimator.setIndices(indices);
  if (options.neighbourhood == NeighbourhoodKind::MeshRings) {
    estimator.setSearchMethod(std::make_shared<MeshRingSearch<pcl::PointXYZ>>(topology));
  } else if (options.neighbourhood == NeighbourhoodKind::Grid) {
    estimator.setSearchMethod(
        std::make_shared<OrganizedGridSearch<pcl::PointXYZ>>(options.max_depth_jump));
  } else if (options.kd_tree_search) {
    estimator.setSearchMethod(options.kd_tree_search);
  } else {
    estimator.setSearchMethod(std::make_shared<KdTreeSearch<pcl::PointXYZ>>());
  }
  if (options.radius > 0.0) {
    estimator.setRadiusSearch(options.radius);
    estimator.setRadiusSearchMaxNeighbours(options.max_neighbours);
    estimator.setRadiusSearchMinNeighbours(options.min_neighbours);
  } else {
    estimator.setKSearch(options.k);
  }
  // The orientation by default, and the spanning tree's seeds' or the faces' fallback.
  const Eigen::Vector3f v = localViewpoint(cloud, options).cast<float>();
  estimator.setViewPoint(v.x(), v.y(), v.z());
  if (options.up) estimator.setUpDirection(options.up->x(), options.up->y(), options.up->z());
  if (options.orientation == NormalOrientation::Up) {
    estimator.setOrientationUp();
  } else if (options.orientation == NormalOrientation::SpanningTree) {
    // Over the mesh's rings when there is a mesh, else the estimator's own neighbourhoods (the
    // grid's steps, or the nearest points in space).
    estimator.setOrientationSpanningTree(
        kSpanningTreeNeighbours, options.seed_facing_viewpoint,
        topology ? std::make_shared<MeshRingSearch<pcl::PointXYZ>>(topology) : nullptr);
  } else if (topology && options.orientation == NormalOrientation::MeshFaces) {
    estimator.setOrientationMesh(topology);
  }
  estimator.setNumberOfThreads(options.threads);
}

/** Turns every normal to n . up >= 0 (the grid path, which orients towards the sensor). */
void orientUp(pcl::PointCloud<pcl::Normal>& normals, const std::optional<Eigen::Vector3d>& up) {
  const Eigen::Vector3f u = up.value_or(Eigen::Vector3d::UnitZ()).cast<float>();
  for (pcl::Normal& n : normals) {
    if (n.getNormalVector3fMap().dot(u) < 0.0f) n.getNormalVector3fMap() *= -1.0f;
  }
}

}  // namespace

int gridWindowRadius(int k) {
  int radius = 1;
  while ((2 * radius + 1) * (2 * radius + 1) < k) ++radius;
  return radius;
}

LocalFitResult fitLocalSurfaces(const LocalCloud& local,
                                const std::shared_ptr<const MeshTopology>& topology,
                                const LocalFitOptions& options) {
  return fitLocalSurfaces(local, topology, options, nullptr);
}

LocalFitResult fitLocalSurfaces(const LocalCloud& local,
                                const std::shared_ptr<const MeshTopology>& topology,
                                const LocalFitOptions& options, const pcl::IndicesPtr& indices) {
  const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud = local.points;
  if (options.neighbourhood == NeighbourhoodKind::MeshRings && !topology) {
    throw pcl::BadArgumentException("mesh-ring neighbourhoods need a mesh (faces)");
  }
  if (!(options.radius >= 0.0) || (options.radius == 0.0 && options.k < 1)) {
    throw pcl::BadArgumentException("k must be >= 1, or the radius > 0");
  }
  if (!cloud || cloud->empty()) throw pcl::BadArgumentException("the cloud is empty");
  LocalFitResult result;
  if (options.method == LocalFitMethod::PCA && options.neighbourhood == NeighbourhoodKind::Grid &&
      options.radius == 0.0 && !indices) {
    OrganizedNormalOptions grid;
    grid.window_radius = gridWindowRadius(options.k);
    grid.max_depth_jump = options.max_depth_jump;
    grid.threads = options.threads;
    grid.positions = local.positions;
    // Unset: the cloud's sensor origin (already in its local frame).
    if (options.viewpoint) grid.viewpoint = localViewpoint(local, options);
    OrganizedNormalResult normals = computeOrganizedPCANormals(cloud, grid);
    result.normals = std::move(normals.normals);
    result.failed_points = normals.failed_points;
    if (options.orientation == NormalOrientation::Up) orientUp(result.normals, options.up);
    if (options.orientation == NormalOrientation::SpanningTree) {
      ConsistentOrientationOptions tree;
      if (options.seed_facing_viewpoint)
        tree.viewpoint = grid.viewpoint.value_or(cloud->sensor_origin_.head<3>().cast<double>());
      else
        tree.up = options.up;
      tree.threads = options.threads;
      result.orientation = orientNormalsConsistently(*normals.grid, result.normals, tree);
    }
    return result;
  }
  if (options.method == LocalFitMethod::PCA) {
    PCANormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
    configure(estimator, local, topology, options, indices);
    estimator.compute(result.normals);
    result.failed_points = estimator.getFailedPoints();
    result.orientation = estimator.getOrientationReport();
  } else if (options.method == LocalFitMethod::Robust) {
    RobustNormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
    configure(estimator, local, topology, options, indices);
    estimator.setCloudPoints(options.cloud_points);
    estimator.setReportReaches(options.report_reaches);
    estimator.compute(result.normals);
    result.failed_points = estimator.getFailedPoints();
    result.orientation = estimator.getOrientationReport();
    result.scales = estimator.getScales();
    result.confidences = estimator.getConfidences();
    result.reaches = estimator.getReaches();
  } else {
    QuadricNormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
    configure(estimator, local, topology, options, indices);
    estimator.computeWithCurvatures(result.normals, result.curvatures);
    result.failed_points = estimator.getFailedPoints();
    result.fallback_points = estimator.getFallbackPoints();
    result.orientation = estimator.getOrientationReport();
  }
  if (result.normals.size() != (indices ? indices->size() : cloud->size())) {
    throw pcl::ComputeFailedException("normal estimation failed (see the PCL error above)");
  }
  return result;
}

LocalFitResult fitLocalSurfacesInSlices(const LocalCloud& cloud,
                                        const std::shared_ptr<const MeshTopology>& topology,
                                        const LocalFitOptions& options, std::size_t slice_points,
                                        const LocalFitSlice& take) {
  const std::size_t n = cloud.points ? cloud.points->size() : 0;
  LocalFitResult total;
  const auto add = [&](std::size_t first, LocalFitResult& slice) {
    total.failed_points += slice.failed_points;
    total.fallback_points += slice.fallback_points;
    total.orientation = slice.orientation;
    take(first, slice);
  };
  // Robust's wider planes, and a mesh's reference normals for the orientation, are made for the
  // whole surface at every compute.
  if (options.neighbourhood != NeighbourhoodKind::KdTree ||
      options.method == LocalFitMethod::Robust || topology ||
      options.orientation == NormalOrientation::SpanningTree || slice_points == 0 ||
      n <= slice_points) {
    LocalFitResult whole = fitLocalSurfaces(cloud, topology, options);
    add(0, whole);
    return total;
  }
  LocalFitOptions shared = options;  // one tree, built by the first slice
  if (!shared.kd_tree_search)
    shared.kd_tree_search = std::make_shared<KdTreeSearch<pcl::PointXYZ>>();
  for (std::size_t first = 0; first < n; first += slice_points) {
    auto indices = std::make_shared<pcl::Indices>(std::min(slice_points, n - first));
    std::iota(indices->begin(), indices->end(), static_cast<pcl::index_t>(first));
    LocalFitResult slice = fitLocalSurfaces(cloud, topology, shared, indices);
    add(first, slice);
  }
  return total;
}

}  // namespace pcl_ddg
