#pragma once
#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <string>

#include "pcl_ddg/search/mesh_ring_search.h"
#include "pcl_ddg/search/visit_stamps.h"

namespace pcl_ddg {

template <typename PointT>
MeshRingSearch<PointT>::MeshRingSearch(std::shared_ptr<const MeshTopology> topology)
    : pcl::search::Search<PointT>("MeshRingSearch", false), topology_(std::move(topology)) {
  if (!topology_) throw pcl::BadArgumentException("MeshRingSearch needs a mesh topology");
}

template <typename PointT>
MeshRingSearch<PointT>::MeshRingSearch(const pcl::PolygonMesh& mesh)
    : MeshRingSearch(std::make_shared<const MeshTopology>(mesh)) {}

template <typename PointT>
void MeshRingSearch<PointT>::setInputCloud(const PointCloudConstPtr& cloud,
                                           const IndicesConstPtr& indices) {
  if (!cloud || cloud->size() != static_cast<std::size_t>(topology_->numVertices())) {
    throw pcl::BadArgumentException(
        "MeshRingSearch: the cloud has " + std::to_string(cloud ? cloud->size() : 0) +
        " points for a mesh of " + std::to_string(topology_->numVertices()) + " vertices");
  }
  if (indices && !indices->empty()) {
    throw pcl::BadArgumentException(
        "MeshRingSearch searches the whole mesh: indices are not supported");
  }
  this->input_ = cloud;
  this->indices_.reset();
  finite_.resize(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i)
    finite_[i] = pcl::isXYZFinite((*cloud)[i]) ? 1 : 0;
}

template <typename PointT>
bool MeshRingSearch<PointT>::isSearchable(pcl::index_t index) const {
  if (!this->input_) {
    PCL_ERROR("[pcl_ddg::MeshRingSearch] no input cloud set\n");
    return false;
  }
  if (index < 0 || index >= static_cast<pcl::index_t>(finite_.size())) {
    PCL_ERROR("[pcl_ddg::MeshRingSearch] query index %d is not a vertex of the mesh\n",
              static_cast<int>(index));
    return false;
  }
  return finite_[index] != 0;
}

template <typename PointT>
bool MeshRingSearch<PointT>::isQueryCloud(const PointCloud& cloud) const {
  if (&cloud == this->input_.get()) return true;
  PCL_ERROR("[pcl_ddg::MeshRingSearch] queries must be vertices of the search's own input cloud\n");
  return false;
}

template <typename PointT>
float MeshRingSearch<PointT>::squaredDistance(pcl::index_t a, pcl::index_t b) const {
  return ((*this->input_)[a].getVector3fMap() - (*this->input_)[b].getVector3fMap()).squaredNorm();
}

template <typename PointT>
int MeshRingSearch<PointT>::nearestKSearch(pcl::index_t index, int k, pcl::Indices& k_indices,
                                           std::vector<float>& k_sqr_distances) const {
  k_indices.clear();
  k_sqr_distances.clear();
  if (k <= 0 || !isSearchable(index)) return 0;
  detail::VisitStamps& visited = detail::VisitStamps::forThisThread(topology_->numVertices());
  visited.startQuery();
  visited.visit(index);
  k_indices.push_back(index);
  // k_indices holds whole rings; [ring_begin, size) is the newest one.
  std::size_t ring_begin = 0;
  while (k_indices.size() < static_cast<std::size_t>(k)) {
    const std::size_t ring_end = k_indices.size();
    for (std::size_t i = ring_begin; i < ring_end; ++i) {
      for (const int neighbour : topology_->neighbours(k_indices[i])) {
        if (visited.visit(neighbour) && finite_[neighbour]) k_indices.push_back(neighbour);
      }
    }
    if (k_indices.size() == ring_end) break;  // the component is exhausted
    ring_begin = ring_end;
  }
  k_sqr_distances.resize(k_indices.size());
  for (std::size_t i = 0; i < k_indices.size(); ++i)
    k_sqr_distances[i] = squaredDistance(index, k_indices[i]);
  if (k_indices.size() > static_cast<std::size_t>(k)) {
    // Keep the nearest members of the last ring: sort that ring's (distance, index) pairs.
    const std::size_t keep = static_cast<std::size_t>(k) - ring_begin;
    auto closer = [&](std::size_t a, std::size_t b) {
      return k_sqr_distances[a] < k_sqr_distances[b] ||
             (k_sqr_distances[a] == k_sqr_distances[b] && k_indices[a] < k_indices[b]);
    };
    // Selection in place: the last ring is short (a few dozen vertices), so this is cheap.
    for (std::size_t i = ring_begin; i < ring_begin + keep; ++i) {
      std::size_t best = i;
      for (std::size_t j = i + 1; j < k_indices.size(); ++j) {
        if (closer(j, best)) best = j;
      }
      std::swap(k_indices[i], k_indices[best]);
      std::swap(k_sqr_distances[i], k_sqr_distances[best]);
    }
    k_indices.resize(k);
    k_sqr_distances.resize(k);
  }
  return static_cast<int>(k_indices.size());
}

template <typename PointT>
int MeshRingSearch<PointT>::nearestKSearch(const PointCloud& cloud, pcl::index_t index, int k,
                                           pcl::Indices& k_indices,
                                           std::vector<float>& k_sqr_distances) const {
  if (!isQueryCloud(cloud)) {
    k_indices.clear();
    k_sqr_distances.clear();
    return 0;
  }
  return nearestKSearch(index, k, k_indices, k_sqr_distances);
}

template <typename PointT>
int MeshRingSearch<PointT>::nearestKSearch(const PointT&, int, pcl::Indices& k_indices,
                                           std::vector<float>& k_sqr_distances) const {
  PCL_ERROR(
      "[pcl_ddg::MeshRingSearch] a point query has no place on the mesh: query by vertex index\n");
  k_indices.clear();
  k_sqr_distances.clear();
  return 0;
}

template <typename PointT>
int MeshRingSearch<PointT>::radiusSearch(pcl::index_t index, double radius, pcl::Indices& k_indices,
                                         std::vector<float>& k_sqr_distances,
                                         unsigned int max_nn) const {
  k_indices.clear();
  k_sqr_distances.clear();
  if (!(radius >= 0.0) || !isSearchable(index)) return 0;
  const double squared_radius = radius * radius;
  detail::VisitStamps& visited = detail::VisitStamps::forThisThread(topology_->numVertices());
  visited.startQuery();
  visited.visit(index);
  k_indices.push_back(index);
  k_sqr_distances.push_back(0.0f);
  // Breadth-first, expanding only from vertices inside the ball.
  for (std::size_t i = 0; i < k_indices.size(); ++i) {
    for (const int neighbour : topology_->neighbours(k_indices[i])) {
      if (!visited.visit(neighbour) || !finite_[neighbour]) continue;
      const float d = squaredDistance(index, neighbour);
      if (d > squared_radius) continue;
      k_indices.push_back(neighbour);
      k_sqr_distances.push_back(d);
    }
  }
  if (this->sorted_results_) this->sortResults(k_indices, k_sqr_distances);
  if (max_nn > 0 && k_indices.size() > max_nn) {
    k_indices.resize(max_nn);
    k_sqr_distances.resize(max_nn);
  }
  return static_cast<int>(k_indices.size());
}

template <typename PointT>
int MeshRingSearch<PointT>::radiusSearch(const PointCloud& cloud, pcl::index_t index, double radius,
                                         pcl::Indices& k_indices,
                                         std::vector<float>& k_sqr_distances,
                                         unsigned int max_nn) const {
  if (!isQueryCloud(cloud)) {
    k_indices.clear();
    k_sqr_distances.clear();
    return 0;
  }
  return radiusSearch(index, radius, k_indices, k_sqr_distances, max_nn);
}

template <typename PointT>
int MeshRingSearch<PointT>::radiusSearch(const PointT&, double, pcl::Indices& k_indices,
                                         std::vector<float>& k_sqr_distances, unsigned int) const {
  PCL_ERROR(
      "[pcl_ddg::MeshRingSearch] a point query has no place on the mesh: query by vertex index\n");
  k_indices.clear();
  k_sqr_distances.clear();
  return 0;
}

}  // namespace pcl_ddg

#define PCL_DDG_INSTANTIATE_MeshRingSearch(T) template class pcl_ddg::MeshRingSearch<T>;
