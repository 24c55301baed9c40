#include "pcl_ddg/tiling/tile_certificate.h"

#include <algorithm>

namespace pcl_ddg {

double haloReach(const Eigen::Vector3d& q, const Eigen::AlignedBox3d& halo_box,
                 const Eigen::AlignedBox3d& bounds) {
  double reach = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d) {
    if (halo_box.min()[d] > bounds.min()[d]) reach = std::min(reach, q[d] - halo_box.min()[d]);
    if (halo_box.max()[d] < bounds.max()[d]) reach = std::min(reach, halo_box.max()[d] - q[d]);
  }
  return reach;
}

LookingKdTree::LookingKdTree(std::size_t points, int k)
    : k_(k), squared_kth_(points, std::numeric_limits<float>::infinity()) {}

int LookingKdTree::nearestKSearch(const PointCloud& cloud, pcl::index_t index, int k,
                                  pcl::Indices& indices, std::vector<float>& squared) const {
  const int found = KdTreeSearch<pcl::PointXYZ>::nearestKSearch(cloud, index, k, indices, squared);
  const auto slot = static_cast<std::size_t>(index);
  if (k == k_ && found >= k && slot < squared_kth_.size()) squared_kth_[slot] = squared[found - 1];
  return found;
}

}  // namespace pcl_ddg
