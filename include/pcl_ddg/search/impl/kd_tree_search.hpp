#pragma once
#include <pcl/common/point_tests.h>

#include <algorithm>

#include "pcl_ddg/search/kd_tree_search.h"

namespace pcl_ddg {

template <typename PointT>
void KdTreeSearch<PointT>::setInputCloud(const PointCloudConstPtr& cloud,
                                         const IndicesConstPtr& indices) {
  this->input_ = cloud;
  this->indices_ = indices;
  static_assert(sizeof(PointT) % sizeof(float) == 0, "PCL points are floats");
  if (!indices && cloud && !cloud->empty() &&
      std::all_of(cloud->begin(), cloud->end(),
                  [](const PointT& p) { return pcl::isXYZFinite(p); })) {
    // Every point, in order: indexed from where it lies (x, y, z are consecutive floats in PCL's
    // point types), not first copied.
    tree_ = std::make_shared<const detail::PointKdTree>(
        &(*cloud)[0].x, sizeof(PointT) / sizeof(float), cloud->size());
    return;
  }
  std::vector<float> xyz;
  std::vector<pcl::index_t> ids;
  const std::size_t candidates = indices ? indices->size() : (cloud ? cloud->size() : 0);
  xyz.reserve(3 * candidates);
  ids.reserve(candidates);
  for (std::size_t i = 0; i < candidates; ++i) {
    const auto id = indices ? (*indices)[i] : static_cast<pcl::index_t>(i);
    const PointT& p = (*cloud)[id];
    if (!pcl::isXYZFinite(p)) continue;
    xyz.insert(xyz.end(), {p.x, p.y, p.z});
    ids.push_back(id);
  }
  tree_ = std::make_shared<const detail::PointKdTree>(std::move(xyz), std::move(ids));
}

template <typename PointT>
int KdTreeSearch<PointT>::nearestKSearch(const PointT& point, int k, pcl::Indices& k_indices,
                                         std::vector<float>& k_sqr_distances) const {
  if (!tree_ || !pcl::isXYZFinite(point)) {
    k_indices.clear();
    k_sqr_distances.clear();
    return 0;
  }
  const float query[3] = {point.x, point.y, point.z};
  return tree_->nearestK(query, k, k_indices, k_sqr_distances);
}

template <typename PointT>
int KdTreeSearch<PointT>::radiusSearch(const PointT& point, double radius, pcl::Indices& k_indices,
                                       std::vector<float>& k_sqr_distances,
                                       unsigned int max_nn) const {
  if (!tree_ || !pcl::isXYZFinite(point)) {
    k_indices.clear();
    k_sqr_distances.clear();
    return 0;
  }
  const float query[3] = {point.x, point.y, point.z};
  return tree_->withinRadius(query, radius, k_indices, k_sqr_distances, max_nn,
                             this->sorted_results_);
}

}  // namespace pcl_ddg

#define PCL_DDG_INSTANTIATE_KdTreeSearch(T) template class pcl_ddg::KdTreeSearch<T>;
