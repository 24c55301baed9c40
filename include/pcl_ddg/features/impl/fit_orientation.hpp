#pragma once
#include <pcl/common/point_tests.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "pcl_ddg/features/fit_orientation.h"
#include "pcl_ddg/search/mesh_ring_search.h"

namespace pcl_ddg {
namespace detail {

template <typename PointInT>
bool FitOrientation<PointInT>::prepare(const typename Cloud::ConstPtr& input,
                                       const Eigen::Matrix3Xd* positions, bool separate_surface,
                                       const typename Search::Ptr& search,
                                       const Eigen::Vector3d& viewpoint,
                                       const std::string& estimator) {
  viewpoint_ = viewpoint;
  std::shared_ptr<const MeshTopology> faces = mesh;
  used_ = policy;
  if (!chosen && viewpoint_given) used_ = NormalOrientation::Viewpoint;
  if (!chosen && !viewpoint_given) {
    const auto ring_search = std::dynamic_pointer_cast<MeshRingSearch<PointInT>>(search);
    used_ = ring_search ? NormalOrientation::MeshFaces : NormalOrientation::Viewpoint;
    if (ring_search) faces = ring_search->topologyPtr();
  }
  reference_normals_.resize(3, 0);
  report_ = ConsistentOrientationReport();
  if (used_ == NormalOrientation::MeshFaces) {
    if (faces->numVertices() != static_cast<int>(input->size())) {
      PCL_ERROR("[pcl_ddg::%s] the orientation mesh has %d vertices for %zu input points\n",
                estimator.c_str(), faces->numVertices(), input->size());
      return false;
    }
    if (positions) {
      reference_normals_ = meshOrientationNormals(*faces, *positions);
    } else {
      Eigen::Matrix3Xd floats(3, input->size());
      for (std::size_t i = 0; i < input->size(); ++i)
        floats.col(i) = (*input)[i].getVector3fMap().template cast<double>();
      reference_normals_ = meshOrientationNormals(*faces, floats);
    }
  }
  if (used_ != NormalOrientation::SpanningTree) return true;
  if (tree_neighbours < 1) {
    PCL_ERROR("[pcl_ddg::%s] the spanning tree needs at least 1 neighbour per point, not %d\n",
              estimator.c_str(), tree_neighbours);
    return false;
  }
  if (!tree_graph && separate_surface) {
    // The search method answers in the surface's indices, which are not the graph's points.
    PCL_ERROR(
        "[pcl_ddg::%s] a spanning tree over a separate search surface needs a graph over "
        "the input (setOrientationSpanningTree's third argument)\n",
        estimator.c_str());
    return false;
  }
  if (tree_graph && tree_graph->getInputCloud() != input) tree_graph->setInputCloud(input);
  return true;
}

template <typename PointInT>
bool FitOrientation<PointInT>::orient(Eigen::Vector3d& n, pcl::index_t index,
                                      const Eigen::Vector3d& p) const {
  double agreement = 0.0;
  if (used_ == NormalOrientation::Up ||
      (used_ == NormalOrientation::SpanningTree && up && !seed_facing_viewpoint)) {
    agreement = n.dot(up.value_or(Eigen::Vector3d::UnitZ()));
  }
  if (reference_normals_.cols() > 0) agreement = n.dot(reference_normals_.col(index));
  if (agreement == 0.0) agreement = n.dot(viewpoint_ - p);  // no face normal there
  if (agreement >= 0.0) return false;
  n = -n;
  return true;
}

template <typename PointInT>
void FitOrientation<PointInT>::makeConsistent(const Search& search, const Cloud& input,
                                              const pcl::Indices& indices, int threads,
                                              pcl::PointCloud<pcl::Normal>& normals) {
  if (used_ != NormalOrientation::SpanningTree) return;
  const int count = static_cast<int>(indices.size());
  const int k = tree_neighbours;
  const Search& graph = tree_graph ? *tree_graph : search;
  pcl::PointCloud<pcl::PointXYZ> points;
  points.resize(indices.size());
  std::vector<int> slot(input.size(), -1);  // input index -> query number
  for (int i = 0; i < count; ++i) {
    slot[indices[i]] = i;
    points[i].getVector3fMap() = input[indices[i]].getVector3fMap();
  }
  // Each point's neighbours fill its own slots: the graph does not depend on the threads.
  std::vector<std::pair<int, int>> edges(static_cast<std::size_t>(count) * k, {-1, -1});
#pragma omp parallel num_threads(threads)
  {
    pcl::Indices found;
    std::vector<float> distances;
#pragma omp for schedule(dynamic, 1024)
    for (int i = 0; i < count; ++i) {
      if (!pcl::isNormalFinite(normals[i]) || !pcl::isXYZFinite(points[i])) continue;
      found.resize(k + 1);  // searches may fill without resizing, as PCL's allow
      distances.resize(k + 1);
      const int answered = graph.nearestKSearch(input, indices[i], k + 1, found, distances);
      int filled = 0;
      for (int n = 0; n < std::min(answered, static_cast<int>(found.size())); ++n) {
        const pcl::index_t j = found[n];
        if (filled == k || slot[j] < 0 || slot[j] == i) continue;
        edges[static_cast<std::size_t>(i) * k + filled++] = {i, slot[j]};
      }
    }
  }
  edges.erase(std::remove(edges.begin(), edges.end(), std::pair<int, int>(-1, -1)), edges.end());
  ConsistentOrientationOptions options;
  if (seed_facing_viewpoint)
    options.viewpoint = viewpoint_;
  else
    options.up = up;
  report_ = orientNormalsConsistently(points, normals, edges, options);
}

}  // namespace detail
}  // namespace pcl_ddg
