#pragma once
// The same estimator run with topological (mesh-ring) and Euclidean (kd-tree) neighbourhoods,
// and how much the two differ at every vertex: where a scan's surface passes close to another
// part of itself (thin walls, folds, fingers), Euclidean neighbourhoods mix both sheets.
#include <Eigen/Core>
#include <cstdint>

#include "pcl_ddg/features/local_fit.h"

namespace pcl_ddg {

struct NeighbourhoodComparison {
  /** Degrees between the two normals (both oriented like the mesh faces); NaN where either failed.
   */
  Eigen::VectorXd angle_difference;
  /** Jaccard overlap |A n B| / |A u B| of the two neighbour sets, in [0, 1]. */
  Eigen::VectorXd overlap;

  struct Summary {
    std::int64_t compared = 0;                                       ///< vertices with both normals
    double mean = 0.0, median = 0.0, percentile95 = 0.0, max = 0.0;  ///< degrees
    double share_over_5 = 0.0, share_over_30 = 0.0;  ///< fractions of compared vertices
    double mean_overlap = 0.0;                       ///< over all vertices
  } summary;

  LocalFitResult mesh_rings, kd_tree;
};

/** Runs options.method (k or radius of options) with both neighbourhoods; options.neighbourhood
 *  is ignored. topology is required (one vertex per point). */
NeighbourhoodComparison compareNeighbourhoods(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                                              const std::shared_ptr<const MeshTopology>& topology,
                                              LocalFitOptions options);

}  // namespace pcl_ddg
