#pragma once
// Consistent normal orientation without a single viewpoint (Hoppe et al. 1992), for merged or
// multi-view clouds: a minimum spanning tree over a neighbour graph weighted by 1 - |n_i . n_j|
// (nearly parallel normals first), and each normal is flipped to agree with its parent in the
// tree. Each connected component is seeded at its highest point (largest z), whose normal is
// turned up (+z), or, given a viewpoint, at the point whose normal faces it most squarely, turned
// towards it; a component is oriented on its own.
//
// The graph is the k nearest neighbours in space, or the mesh's edges, or an organized cloud's
// jump-free pixel steps (OrganizedGridSearch), or one the caller gives. Points with a non-finite
// coordinate or normal take no part and keep their normal.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/search/organized_grid_search.h"

namespace pcl_ddg {

struct ConsistentOrientationOptions {
  int k = 10;  ///< neighbours per point of the k-nearest graph
  /** Seeds face this point; unset: each component's highest point faces +z. */
  std::optional<Eigen::Vector3d> viewpoint;
  unsigned int threads = 0;  ///< for the k-nearest search; 0: all cores
};

struct ConsistentOrientationReport {
  std::int64_t oriented_points = 0;  ///< finite point and normal
  std::int64_t flipped_points = 0;   ///< normals turned around
  std::int64_t components = 0;       ///< of the graph over the oriented points
  double flippedShare() const {
    return oriented_points > 0 ? static_cast<double>(flipped_points) / oriented_points : 0.0;
  }
};

/** Over the k-nearest-neighbour graph. Throws pcl::BadArgumentException unless k >= 1 and the
 *  normals match the cloud in size. */
ConsistentOrientationReport orientNormalsConsistently(
    const pcl::PointCloud<pcl::PointXYZ>& cloud, pcl::PointCloud<pcl::Normal>& normals,
    const ConsistentOrientationOptions& options = ConsistentOrientationOptions());

/** Over the edges of a mesh (one vertex per point). */
ConsistentOrientationReport orientNormalsConsistently(
    const MeshTopology& topology, const pcl::PointCloud<pcl::PointXYZ>& cloud,
    pcl::PointCloud<pcl::Normal>& normals,
    const ConsistentOrientationOptions& options = ConsistentOrientationOptions());

/** Over the given graph, pairs of point indices (e.g. each point's neighbours from whatever search
 *  an estimator uses). Throws pcl::BadArgumentException for an index outside the cloud. */
ConsistentOrientationReport orientNormalsConsistently(
    const pcl::PointCloud<pcl::PointXYZ>& cloud, pcl::PointCloud<pcl::Normal>& normals,
    const std::vector<std::pair<int, int>>& edges,
    const ConsistentOrientationOptions& options = ConsistentOrientationOptions());

/** Over the pixel grid of the search's organized cloud (its jump-free steps). */
ConsistentOrientationReport orientNormalsConsistently(
    const OrganizedGridSearch<pcl::PointXYZ>& grid, pcl::PointCloud<pcl::Normal>& normals,
    const ConsistentOrientationOptions& options = ConsistentOrientationOptions());

}  // namespace pcl_ddg
