#pragma once
/** \file
 * The same estimator run with topological neighbourhoods (mesh rings, or an organized cloud's
 * pixel grid) and Euclidean ones (kd-tree), and how much the two differ at every point: where a
 * scan's surface passes close to another part of itself (thin walls, folds, fingers), or a frame
 * has a depth jump, Euclidean neighbourhoods mix both sides.
 */
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

  LocalFitResult topological, kd_tree;
};

/** Runs options.method (k or radius of options) with both neighbourhoods; options.neighbourhood
 *  is ignored. The topological one is the mesh's rings with a topology (one vertex per point),
 *  else the pixel grid of an organized cloud (PCA over its window, as fitLocalSurfaces does;
 *  the overlap is then of that window's pixels); throws pcl::BadArgumentException for neither. */
NeighbourhoodComparison compareNeighbourhoods(const LocalCloud& local,
                                              const std::shared_ptr<const MeshTopology>& topology,
                                              LocalFitOptions options);

}  // namespace pcl_ddg
