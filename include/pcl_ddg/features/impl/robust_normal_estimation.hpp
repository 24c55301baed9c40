#pragma once
#include <limits>

#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/features/robust_plane_fit.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
void RobustNormalEstimation<PointInT, PointOutT>::computeFeature(PointCloudOut& output) {
  using Outcome = typename LocalFitEstimation<PointInT, PointOutT>::FitOutcome;
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  scales_.assign(output.size(), nan);
  confidences_.assign(output.size(), nan);
  this->fitEachNeighbourhood(
      output, [this, &output](const Eigen::Matrix3Xd& neighbours, int count, pcl::index_t index,
                              const Eigen::Vector3d& position, std::size_t i) {
        if (!position.allFinite()) return Outcome::Failed;
        const RobustPlaneFit plane = fitRobustPlane(neighbours, count);
        if (!plane.valid) return Outcome::Failed;
        Eigen::Vector3d normal = plane.normal;
        this->orient(normal, index, position);
        PointOutT& out = output[i];
        out.normal_x = static_cast<float>(normal.x());
        out.normal_y = static_cast<float>(normal.y());
        out.normal_z = static_cast<float>(normal.z());
        out.curvature = static_cast<float>(plane.surface_variation);
        scales_[i] = static_cast<float>(plane.scale);
        confidences_[i] = static_cast<float>(plane.confidence);
        return Outcome::Fitted;
      });
  this->makeOrientationConsistent(output, [](std::size_t) {});
}

template <typename PointInT, typename PointOutT>
void RobustNormalEstimation<PointInT, PointOutT>::setInvalid(PointOutT& point) const {
  point.normal_x = point.normal_y = point.normal_z = point.curvature =
      std::numeric_limits<float>::quiet_NaN();
}

}  // namespace pcl_ddg

#define PCL_DDG_INSTANTIATE_RobustNormalEstimation(T, NT) \
  template class pcl_ddg::RobustNormalEstimation<T, NT>;
