#pragma once
/** \file
 * Consistent normal orientation without a single viewpoint (Hoppe et al. 1992), for merged or
 * multi-view clouds: a minimum spanning tree over a neighbour graph weighted by 1 - |n_i . n_j|
 * (nearly parallel normals first), and each normal is flipped to agree with its parent in the
 * tree. Without a reference, each connected component is seeded at its highest point (largest z),
 * whose normal is turned up (+z); a component is oriented on its own.
 *
 * With a reference (a viewpoint, or an up direction for aerial data) the reference decides every
 * point it can: a point is confident when |n . d| >= confidence, d the unit direction to the
 * viewpoint (or up), and its normal is turned to n . d >= 0 whatever the tree says, because
 * propagation over a tree flips whole regions across trees, walls and thin parts. The tree only
 * fills in the ambiguous points: each connected region of them (over tree edges) is made
 * consistent from its most confident point, and takes the sign that agrees with the reference
 * most, sum over the region of n . d >= 0 (each point's own sign is a coin toss there, the sum is
 * not); a tie goes to the majority of its tree edges to confident points. Confident points are
 * signed as by the reference alone.
 *
 * The graph is the k nearest neighbours in space, or the mesh's edges, or an organized cloud's
 * jump-free pixel steps (OrganizedGridSearch), or one the caller gives. Points with a non-finite
 * coordinate or normal take no part and keep their normal.
 */
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
  /** The reference: normals face this point where it is confident (see above). */
  std::optional<Eigen::Vector3d> viewpoint;
  /** The reference when no viewpoint is set: normals have n . up >= 0 where confident. Neither
   *  set: each component's highest point faces +z and the tree decides the rest. */
  std::optional<Eigen::Vector3d> up;
  /** |n . d| from which the reference decides a point's sign: 0.1 = sin 5.7 deg, more than a
   *  fitted normal's usual error, so the reference's sign there is not a coin toss. */
  double confidence = 0.1;
  unsigned int threads = 0;  ///< for the k-nearest search; 0: all cores
};

struct ConsistentOrientationReport {
  std::int64_t oriented_points = 0;    ///< finite point and normal
  std::int64_t flipped_points = 0;     ///< normals turned around
  std::int64_t components = 0;         ///< of the graph over the oriented points
  std::int64_t confident_points = 0;   ///< with a reference: signed by it
  std::int64_t propagated_flips = 0;   ///< with a reference: ambiguous points the tree turned
  std::int64_t ambiguous_regions = 0;  ///< with a reference: regions of ambiguous points
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
