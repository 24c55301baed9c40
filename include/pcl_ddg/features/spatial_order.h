#pragma once
/** \file
 * An order in which to visit points so that consecutive ones are near each other in space: the
 * cells of a grid over their bounding box in Morton (Z-curve) order, points in input order within
 * a cell. Estimators query their neighbourhoods in this order (results still go to each point's
 * own place): on a cloud stored in no spatial order (merged scans, shuffled files) consecutive
 * kd-tree queries then touch the same tree nodes and points, instead of missing the caches.
 */
#include <Eigen/Core>
#include <vector>

namespace pcl_ddg {
namespace detail {

/** A permutation of [0, points.size()): Morton order of grid cells (about eight points per cell,
 *  at most 128 per axis), non-finite points last. Linear time (a counting sort). */
std::vector<int> spatialOrder(const std::vector<Eigen::Vector3f>& points);

}  // namespace detail
}  // namespace pcl_ddg
