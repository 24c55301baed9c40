#pragma once
/** \file
 * Topological neighbourhoods on a mesh, as a PCL search method, so that any pcl::Feature (and
 * pcl::NormalEstimation unchanged) can use them through setSearchMethod.
 *
 *  nearestKSearch(index, k)     the vertex itself, then its 1-ring, 2-ring, ... by breadth-first
 *                               search over the mesh edges; the ring that would overflow k is
 *                               filled in order of Euclidean distance. Results come in ring order
 *                               (the query first); fewer than k on a component smaller than k.
 *  radiusSearch(index, r)       the vertices reachable from the query along edges without leaving
 *                               the Euclidean ball of radius r: a topological ball, which never
 *                               jumps to another sheet of the surface however close it passes.
 *                               Sorted by distance if setSortedResults(true), else in search
 *                               order (nearest rings first); max_nn keeps the first max_nn.
 *
 * Distances are squared and in float, as PCL returns them. Queries are vertex indices of the
 * input cloud; a bare point (not a vertex) has no place on the mesh and fails with PCL_ERROR.
 * Vertices with a non-finite coordinate are never returned and never searched through; a query at
 * one returns nothing. Thread-safe: concurrent queries (pcl::NormalEstimationOMP) use per-thread
 * visit marks, and a query allocates nothing once its output vectors have grown.
 */
#include <pcl/search/search.h>

#include <memory>
#include <vector>

#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

template <typename PointT>
class MeshRingSearch : public pcl::search::Search<PointT> {
 public:
  using Ptr = std::shared_ptr<MeshRingSearch<PointT>>;
  using ConstPtr = std::shared_ptr<const MeshRingSearch<PointT>>;
  using PointCloud = typename pcl::search::Search<PointT>::PointCloud;
  using PointCloudConstPtr = typename pcl::search::Search<PointT>::PointCloudConstPtr;
  using IndicesConstPtr = pcl::IndicesConstPtr;

  /** Searches the vertex graph of topology; the input cloud must have one point per vertex. */
  explicit MeshRingSearch(std::shared_ptr<const MeshTopology> topology);

  /** Builds the topology of mesh (throws pcl_ddg::InvalidMeshException on bad face indices). */
  explicit MeshRingSearch(const pcl::PolygonMesh& mesh);

  const MeshTopology& topology() const { return *topology_; }
  std::shared_ptr<const MeshTopology> topologyPtr() const { return topology_; }

  /** Throws pcl::BadArgumentException unless cloud has one point per mesh vertex; restricting the
   *  search to indices is not supported (the graph is the whole mesh). */
  void setInputCloud(const PointCloudConstPtr& cloud,
                     const IndicesConstPtr& indices = IndicesConstPtr()) override;

  using pcl::search::Search<PointT>::nearestKSearch;
  using pcl::search::Search<PointT>::radiusSearch;

  int nearestKSearch(pcl::index_t index, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;
  int nearestKSearch(const PointCloud& cloud, pcl::index_t index, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;
  /** Not a vertex: fails (PCL_ERROR, 0 results). */
  int nearestKSearch(const PointT& point, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;

  int radiusSearch(pcl::index_t index, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override;
  int radiusSearch(const PointCloud& cloud, pcl::index_t index, double radius,
                   pcl::Indices& k_indices, std::vector<float>& k_sqr_distances,
                   unsigned int max_nn = 0) const override;
  /** Not a vertex: fails (PCL_ERROR, 0 results). */
  int radiusSearch(const PointT& point, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override;

 private:
  bool isSearchable(pcl::index_t index) const;
  bool isQueryCloud(const PointCloud& cloud) const;
  float squaredDistance(pcl::index_t a, pcl::index_t b) const;

  std::shared_ptr<const MeshTopology> topology_;
  std::vector<std::uint8_t> finite_;  ///< per vertex of the input cloud
};

}  // namespace pcl_ddg

#ifdef PCL_NO_PRECOMPILE
#include "pcl_ddg/search/impl/mesh_ring_search.hpp"
#endif
