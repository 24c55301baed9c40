#pragma once
/** \file
 * Euclidean neighbourhoods from a kd-tree (point_kd_tree.h), as a PCL search method: the same
 * answers as pcl::search::KdTree (exact k nearest, squared distances in float), without its
 * per-query overhead (see point_kd_tree.h), so estimators that are parallel over points scale.
 *
 * Non-finite points are never indexed nor returned. With indices in setInputCloud only those
 * points are searched, and an index query (nearestKSearch(i, ...)) means the i-th of them, as in
 * PCL. k nearest are sorted by distance; radius results when setSortedResults(true) (the default).
 * A cloud of finite points searched whole is indexed straight from its points, without the
 * packed copy pcl::search::KdTree makes first.
 */
#include <pcl/search/search.h>

#include <memory>

#include "pcl_ddg/search/point_kd_tree.h"

namespace pcl_ddg {

template <typename PointT>
class KdTreeSearch : public pcl::search::Search<PointT> {
 public:
  using Ptr = std::shared_ptr<KdTreeSearch<PointT>>;
  using PointCloud = typename pcl::search::Search<PointT>::PointCloud;
  using PointCloudConstPtr = typename pcl::search::Search<PointT>::PointCloudConstPtr;
  using IndicesConstPtr = pcl::IndicesConstPtr;

  KdTreeSearch() : pcl::search::Search<PointT>("KdTreeSearch", true) {}

  void setInputCloud(const PointCloudConstPtr& cloud,
                     const IndicesConstPtr& indices = IndicesConstPtr()) override;

  using pcl::search::Search<PointT>::nearestKSearch;
  using pcl::search::Search<PointT>::radiusSearch;

  int nearestKSearch(const PointT& point, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;
  int radiusSearch(const PointT& point, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override;

 private:
  std::shared_ptr<const detail::PointKdTree> tree_;
};

}  // namespace pcl_ddg

#ifdef PCL_NO_PRECOMPILE
#include "pcl_ddg/search/impl/kd_tree_search.hpp"
#endif
