#pragma once
#include <limits>

#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/features/plane_fit.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
void PCANormalEstimation<PointInT, PointOutT>::computeFeature(PointCloudOut& output) {
  using Outcome = typename LocalFitEstimation<PointInT, PointOutT>::FitOutcome;
  this->fitEachNeighbourhood(
      output, [this, &output](const Eigen::Matrix3Xd& neighbours, int count, const pcl::Indices&,
                              pcl::index_t index, const Eigen::Vector3d& position, std::size_t i) {
        PointOutT& out = output[i];
        const PlaneFit plane = fitPlane(neighbours, count);
        if (!plane.valid) return Outcome::Failed;
        Eigen::Vector3d normal = plane.normal;
        this->orient(normal, index, position);
        out.normal_x = static_cast<float>(normal.x());
        out.normal_y = static_cast<float>(normal.y());
        out.normal_z = static_cast<float>(normal.z());
        out.curvature = static_cast<float>(plane.surface_variation);
        return Outcome::Fitted;
      });
  this->makeOrientationConsistent(output, [](std::size_t) {});
}

}  // namespace pcl_ddg

#define PCL_DDG_INSTANTIATE_PCANormalEstimation(T, NT) \
  template class pcl_ddg::PCANormalEstimation<T, NT>;
