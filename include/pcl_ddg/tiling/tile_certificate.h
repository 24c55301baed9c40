#pragma once
/** \file
 * The rule that certifies a tile's fit: a point's neighbourhood found among the points gathered
 * for its tile (the tile's box grown by a halo) is its neighbourhood in the whole cloud when it
 * cannot reach past what was gathered. fitTiles (in memory and out of core) and the Dask runner
 * (python/src/distributed_bindings.cpp) certify by this one rule, so that they write the bytes
 * the whole cloud's fit writes.
 *
 * - Radius r: a halo of r (1 + kRoundingMargin) holds every point of every own point's ball.
 * - k nearest: a point's k-th neighbour among the gathered points is never nearer than its true
 *   k-th neighbour, so the point looks at most that far (widened by the margin, lookingDistance);
 *   the fit holds when that look stays inside the halo box, haloReach: the distance to the nearest
 *   face of the box that does not lie beyond the cloud's bounds (nothing lies beyond those).
 *
 * - Robust normals with k nearest: also the rows its wider planes read, each the nearest 32 of a
 *   node up to twelve steps away along the graph; the reach bounds the ball of every such row.
 *
 * The margin: float squared distances of points that differ in their last bits can round either
 * way, so a point counts as inside only with a relative margin of 1e-5.
 */
#include <pcl/point_types.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pcl_ddg/search/kd_tree_search.h"

namespace pcl_ddg {

constexpr double kRoundingMargin = 1e-5;

/** The halo that certifies radius searches of radius r. */
inline double radiusHalo(double radius) {
  return radius * (1.0 + kRoundingMargin);
}

/** How far a point whose k-th gathered neighbour lies at squared float distance squared_kth
 *  looks (infinity: fewer than k were gathered). */
inline double lookingDistance(float squared_kth) {
  return squared_kth <= std::numeric_limits<float>::max()
             ? std::sqrt(static_cast<double>(squared_kth)) * (1.0 + kRoundingMargin) + 1e-30
             : std::numeric_limits<double>::infinity();
}

/** How far a robust fit looked: its k nearest (squared_kth, as above) or the rows its wider
 *  planes read (reach: RobustNormalEstimation::getReaches, in the same float coordinates),
 *  whichever is farther, widened by the margin. */
inline double lookingDistance(float squared_kth, double reach) {
  if (std::isnan(reach)) return std::numeric_limits<double>::infinity();  // certifies nothing
  return std::max(lookingDistance(squared_kth), reach * (1.0 + kRoundingMargin));
}

/** How far q may look before it could meet a point that was not gathered (see above). */
double haloReach(const Eigen::Vector3d& q, const Eigen::AlignedBox3d& halo_box,
                 const Eigen::AlignedBox3d& bounds);

/**
 * The kd-tree of a tile's fit, which keeps for each index query with the fit's k the squared
 * distance of its k-th neighbour (infinity with fewer than k): the fit's own search says how far
 * each point looked. Thread-safe as the estimators query it (each point its own slot).
 */
class LookingKdTree : public KdTreeSearch<pcl::PointXYZ> {
 public:
  LookingKdTree(std::size_t points, int k);
  using KdTreeSearch<pcl::PointXYZ>::nearestKSearch;
  int nearestKSearch(const PointCloud& cloud, pcl::index_t index, int k, pcl::Indices& indices,
                     std::vector<float>& squared) const override;
  /** The squared distance of point index's k-th neighbour (infinity: not queried, or fewer). */
  float squaredKth(std::size_t index) const { return squared_kth_[index]; }

 private:
  int k_;
  mutable std::vector<float> squared_kth_;
};

}  // namespace pcl_ddg
