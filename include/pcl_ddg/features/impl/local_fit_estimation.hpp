#pragma once
#include <pcl/common/point_tests.h>

#include <algorithm>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "pcl_ddg/features/local_fit_estimation.h"
#include "pcl_ddg/features/plane_fit.h"

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
  const bool defaulted = this->k_ == 0 && this->search_radius_ == 0.0 && defaultK() > 0;
  if (defaulted) this->k_ = defaultK();
  const bool initialised = pcl::Feature<PointInT, PointOutT>::initCompute();
  search_k_ = this->k_;
  if (defaulted) this->k_ = 0;  // applied, not stored (PCL's search reads search_parameter_)
  if (!initialised) return false;
  if (input_positions_ &&
      (this->surface_ != this->input_ ||
       input_positions_->cols() != static_cast<Eigen::Index>(this->input_->size()))) {
    PCL_ERROR(
        "[pcl_ddg::%s] the input positions (%lld) must be the input's (%zu points), and the "
        "input its own search surface\n",
        this->getClassName().c_str(), static_cast<long long>(input_positions_->cols()),
        this->input_->size());
    return false;
  }
  return orientation_.prepare(this->input_, input_positions_.get(), this->surface_ != this->input_,
                              this->tree_, Eigen::Vector3d(vpx_, vpy_, vpz_), this->getClassName());
}

template <typename PointInT, typename PointOutT>
template <typename OnTurn>
void LocalFitEstimation<PointInT, PointOutT>::makeOrientationConsistent(PointCloudOut& output,
                                                                        OnTurn&& on_turn) {
  if (orientation_.used() != NormalOrientation::SpanningTree) return;
  pcl::PointCloud<pcl::Normal> normals;
  normals.resize(output.size());
  for (std::size_t i = 0; i < output.size(); ++i) {
    normals[i].getNormalVector3fMap() =
        Eigen::Vector3f(output[i].normal_x, output[i].normal_y, output[i].normal_z);
  }
  orientation_.makeConsistent(*this->tree_, *this->input_, *this->indices_, threadCount(), normals);
  for (std::size_t i = 0; i < output.size(); ++i) {
    const Eigen::Vector3f before(output[i].normal_x, output[i].normal_y, output[i].normal_z);
    if (!(normals[i].getNormalVector3fMap().dot(before) < 0.0f)) continue;
    output[i].normal_x = normals[i].normal_x;
    output[i].normal_y = normals[i].normal_y;
    output[i].normal_z = normals[i].normal_z;
    on_turn(i);
  }
}

template <typename PointInT, typename PointOutT>
int LocalFitEstimation<PointInT, PointOutT>::threadCount() const {
#ifdef _OPENMP
  if (threads_ == 0) return omp_get_num_procs();
#endif
  return static_cast<int>(threads_);
}

template <typename PointInT, typename PointOutT>
void LocalFitEstimation<PointInT, PointOutT>::fitEachNeighbourhood(
    PointCloudOut& output, const detail::NeighbourhoodFit& fit) {
  detail::NeighbourhoodQueries<PointInT> queries;
  queries.input = this->input_.get();
  queries.surface = this->surface_.get();
  queries.indices = this->indices_.get();
  queries.positions = input_positions_.get();
  queries.tree = this->tree_.get();
  queries.search = &this->search_method_surface_;
  queries.search_parameter = this->search_parameter_;
  queries.radius = this->search_radius_;
  queries.k = searchK();
  queries.max_neighbours = max_neighbours_;
  queries.min_neighbours = min_neighbours_;
  queries.threads = threadCount();
  const detail::FitCounts counts = detail::fitNeighbourhoods(
      queries, [&](const Eigen::Matrix3Xd& neighbours, int count, const pcl::Indices& found,
                   pcl::index_t index, const Eigen::Vector3d& position, std::size_t place) {
        const FitOutcome outcome = fit(neighbours, count, found, index, position, place);
        if (outcome == FitOutcome::Failed) setInvalid(output[place]);
        return outcome;
      });
  output.is_dense = counts.failed == 0;
  failed_points_ = counts.failed;
  fallback_points_ = counts.fell_back;
  if (counts.failed > 0) {
    PCL_WARN(
        "[pcl_ddg::%s] %lld of %zu points could not be estimated (non-finite, or fewer than the "
        "minimum of finite neighbours): their output is NaN\n",
        this->getClassName().c_str(), static_cast<long long>(counts.failed),
        this->indices_->size());
  }
}

}  // namespace pcl_ddg
