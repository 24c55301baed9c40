#pragma once
#include <pcl/common/point_tests.h>

#include <algorithm>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "pcl_ddg/features/local_fit_estimation.h"
#include "pcl_ddg/features/plane_fit.h"
#include "pcl_ddg/features/spatial_order.h"
#include "pcl_ddg/search/mesh_ring_search.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
bool LocalFitEstimation<PointInT, PointOutT>::computePointNormal(
    const pcl::PointCloud<PointInT>& cloud, const pcl::Indices& indices,
    Eigen::Vector4f& plane_parameters, float& curvature) const {
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  // About the first finite point, in double: fitPlane then centres exactly.
  Eigen::Matrix3Xd points(3, indices.size());
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  int count = 0;
  for (const pcl::index_t j : indices) {
    if (!pcl::isXYZFinite(cloud[j])) continue;
    const Eigen::Vector3d p = cloud[j].getVector3fMap().template cast<double>();
    if (count == 0) shift = p;
    points.col(count++) = p - shift;
  }
  const PlaneFit plane = count >= 3 ? fitPlane(points, count) : PlaneFit();
  if (!plane.valid) {
    plane_parameters.setConstant(nan);
    curvature = nan;
    return false;
  }
  const Eigen::Vector3d centroid = plane.centroid + shift;
  plane_parameters << plane.normal.template cast<float>(),
      static_cast<float>(-plane.normal.dot(centroid));
  curvature = static_cast<float>(plane.surface_variation);
  return true;
}

template <typename PointInT, typename PointOutT>
bool LocalFitEstimation<PointInT, PointOutT>::computePointNormal(
    const pcl::PointCloud<PointInT>& cloud, const pcl::Indices& indices, float& nx, float& ny,
    float& nz, float& curvature) const {
  Eigen::Vector4f plane;
  const bool valid = computePointNormal(cloud, indices, plane, curvature);
  nx = plane.x();
  ny = plane.y();
  nz = plane.z();
  return valid;
}

template <typename PointInT, typename PointOutT>
bool LocalFitEstimation<PointInT, PointOutT>::initCompute() {
  if (!pcl::Feature<PointInT, PointOutT>::initCompute()) return false;
  viewpoint_ = Eigen::Vector3d(vpx_, vpy_, vpz_);
  std::shared_ptr<const MeshTopology> mesh = orientation_mesh_;
  used_orientation_ = orientation_;
  if (!orientation_chosen_) {
    const auto ring_search = std::dynamic_pointer_cast<MeshRingSearch<PointInT>>(this->tree_);
    used_orientation_ = ring_search ? NormalOrientation::MeshFaces : NormalOrientation::Viewpoint;
    if (ring_search) mesh = ring_search->topologyPtr();
  }
  if (used_orientation_ == NormalOrientation::MeshFaces) {
    if (mesh->numVertices() != static_cast<int>(this->input_->size())) {
      PCL_ERROR("[pcl_ddg::%s] the orientation mesh has %d vertices for %zu input points\n",
                this->getClassName().c_str(), mesh->numVertices(), this->input_->size());
      return false;
    }
    Eigen::Matrix3Xd positions(3, this->input_->size());
    for (std::size_t i = 0; i < this->input_->size(); ++i) {
      positions.col(i) = (*this->input_)[i].getVector3fMap().template cast<double>();
    }
    reference_normals_ = meshOrientationNormals(*mesh, positions);
  } else {
    reference_normals_.resize(3, 0);
  }
  if (used_orientation_ == NormalOrientation::SpanningTree && spanning_tree_neighbours_ < 1) {
    PCL_ERROR("[pcl_ddg::%s] the spanning tree needs at least 1 neighbour per point, not %d\n",
              this->getClassName().c_str(), spanning_tree_neighbours_);
    return false;
  }
  if (used_orientation_ == NormalOrientation::SpanningTree && !spanning_tree_graph_ &&
      this->surface_ != this->input_) {
    // The search method answers in the surface's indices, which are not the graph's points.
    PCL_ERROR(
        "[pcl_ddg::%s] a spanning tree over a separate search surface needs a graph over "
        "the input (setOrientationSpanningTree's third argument)\n",
        this->getClassName().c_str());
    return false;
  }
  if (used_orientation_ == NormalOrientation::SpanningTree && spanning_tree_graph_ &&
      spanning_tree_graph_->getInputCloud() != this->input_) {
    spanning_tree_graph_->setInputCloud(this->input_);
  }
  orientation_report_ = ConsistentOrientationReport();
  return true;
}

template <typename PointInT, typename PointOutT>
template <typename OnTurn>
void LocalFitEstimation<PointInT, PointOutT>::makeOrientationConsistent(PointCloudOut& output,
                                                                        OnTurn&& on_turn) {
  if (used_orientation_ != NormalOrientation::SpanningTree) return;
  const pcl::Indices& indices = *this->indices_;
  const int count = static_cast<int>(indices.size());
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::PointCloud<pcl::Normal> normals;
  points.resize(indices.size());
  normals.resize(indices.size());
  std::vector<int> slot(this->input_->size(), -1);  // input index -> output index
  for (int i = 0; i < count; ++i) {
    slot[indices[i]] = i;
    points[i].getVector3fMap() = (*this->input_)[indices[i]].getVector3fMap();
    normals[i].getNormalVector3fMap() =
        Eigen::Vector3f(output[i].normal_x, output[i].normal_y, output[i].normal_z);
  }
  // Each point's neighbours fill its own slots: the graph does not depend on the threads.
  const int k = spanning_tree_neighbours_;
  const pcl::search::Search<PointInT>& graph =
      spanning_tree_graph_ ? *spanning_tree_graph_ : *this->tree_;
  std::vector<std::pair<int, int>> edges(static_cast<std::size_t>(count) * k, {-1, -1});
  int threads = static_cast<int>(threads_);
#ifdef _OPENMP
  if (threads == 0) threads = omp_get_num_procs();
#endif
#pragma omp parallel num_threads(threads)
  {
    pcl::Indices found;
    std::vector<float> distances;
#pragma omp for schedule(dynamic, 1024)
    for (int i = 0; i < count; ++i) {
      if (!pcl::isNormalFinite(normals[i]) || !pcl::isXYZFinite(points[i])) continue;
      found.resize(k + 1);  // searches may fill without resizing, as PCL's allow
      distances.resize(k + 1);
      const int answered = graph.nearestKSearch(*this->input_, indices[i], k + 1, found, distances);
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
  if (seed_facing_viewpoint_)
    options.viewpoint = viewpoint_;
  else
    options.up = up_;
  orientation_report_ = orientNormalsConsistently(points, normals, edges, options);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3f before(output[i].normal_x, output[i].normal_y, output[i].normal_z);
    if (!(normals[i].getNormalVector3fMap().dot(before) < 0.0f)) continue;
    output[i].normal_x = normals[i].normal_x;
    output[i].normal_y = normals[i].normal_y;
    output[i].normal_z = normals[i].normal_z;
    on_turn(i);
  }
}

template <typename PointInT, typename PointOutT>
bool LocalFitEstimation<PointInT, PointOutT>::orient(Eigen::Vector3d& n, pcl::index_t index,
                                                     const Eigen::Vector3d& p) const {
  double agreement = 0.0;
  if (used_orientation_ == NormalOrientation::Up ||
      (used_orientation_ == NormalOrientation::SpanningTree && up_ && !seed_facing_viewpoint_)) {
    agreement = n.dot(up_.value_or(Eigen::Vector3d::UnitZ()));
  }
  if (reference_normals_.cols() > 0) agreement = n.dot(reference_normals_.col(index));
  if (agreement == 0.0) agreement = n.dot(viewpoint_ - p);  // no face normal there
  if (agreement >= 0.0) return false;
  n = -n;
  return true;
}

template <typename PointInT, typename PointOutT>
template <typename Fit>
void LocalFitEstimation<PointInT, PointOutT>::fitEachNeighbourhood(PointCloudOut& output,
                                                                   Fit&& fit) {
  const pcl::Indices& indices = *this->indices_;
  const auto& surface = *this->surface_;
  int threads = static_cast<int>(threads_);
#ifdef _OPENMP
  if (threads == 0) threads = omp_get_num_procs();
#endif
  std::int64_t failed = 0, fell_back = 0;
  output.is_dense = true;
  // Queried in space-filling order (each result still goes to its point's place): consecutive
  // queries share tree nodes and neighbours, whatever order the cloud is stored in.
  std::vector<Eigen::Vector3f> query_positions(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i)
    query_positions[i] = (*this->input_)[indices[i]].getVector3fMap();
  const std::vector<int> order = detail::spatialOrder(query_positions);
#pragma omp parallel num_threads(threads) reduction(+ : failed, fell_back)
  {
    // Per-thread buffers, grown once and reused for every point.
    pcl::Indices neighbours;
    std::vector<float> squared_distances;
    Eigen::Matrix3Xd local(3, 64);
#pragma omp for schedule(dynamic, 256)
    for (std::ptrdiff_t visit = 0; visit < static_cast<std::ptrdiff_t>(indices.size()); ++visit) {
      const std::ptrdiff_t i = order[visit];
      const PointInT& query = (*this->input_)[indices[i]];
      FitOutcome outcome = FitOutcome::Failed;
      const bool capped_radius = this->search_radius_ > 0.0 && max_neighbours_ > 0;
      // Sized to k before every search, as pcl::NormalEstimationOMP does: a search may write its
      // answer into them without resizing (PCL's own tests rely on it).
      const auto presize = [&](int size) {
        neighbours.resize(std::max(size, 0));
        squared_distances.resize(std::max(size, 0));
      };
      presize(this->k_);
      int found = !pcl::isXYZFinite(query) ? 0
                  : capped_radius
                      ? this->tree_->radiusSearch(*this->input_, indices[i], this->search_radius_,
                                                  neighbours, squared_distances, max_neighbours_)
                      : this->searchForNeighbors(indices[i], this->search_parameter_, neighbours,
                                                 squared_distances);
      if (this->search_radius_ > 0.0 && pcl::isXYZFinite(query) &&
          found < static_cast<int>(min_neighbours_)) {
        presize(static_cast<int>(min_neighbours_));
        found = this->tree_->nearestKSearch(*this->input_, indices[i],
                                            static_cast<int>(min_neighbours_), neighbours,
                                            squared_distances);
      }
      found = std::min(found, static_cast<int>(neighbours.size()));
      if (found > 0) {
        const Eigen::Vector3d origin = query.getVector3fMap().template cast<double>();
        if (local.cols() < found) local.resize(3, found);
        int count = 0;
        for (int n = 0; n < found; ++n) {
          const pcl::index_t j = neighbours[n];
          if (pcl::isXYZFinite(surface[j])) {
            local.col(count++) = surface[j].getVector3fMap().template cast<double>() - origin;
          }
        }
        outcome = fit(local, count, indices[i], origin, static_cast<std::size_t>(i));
      }
      if (outcome == FitOutcome::Failed) {
        setInvalid(output[i]);
        ++failed;
      } else if (outcome == FitOutcome::FellBack) {
        ++fell_back;
      }
    }
  }
  failed_points_ = failed;
  fallback_points_ = fell_back;
  if (failed > 0) {
    output.is_dense = false;
    PCL_WARN(
        "[pcl_ddg::%s] %lld of %zu points could not be estimated (non-finite, or fewer than the "
        "minimum of finite neighbours): their output is NaN\n",
        this->getClassName().c_str(), static_cast<long long>(failed), indices.size());
  }
}

}  // namespace pcl_ddg
