#pragma once
#include <limits>

#include "pcl_ddg/features/plane_fit.h"
#include "pcl_ddg/features/quadric_fit.h"
#include "pcl_ddg/features/quadric_normal_estimation.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
void QuadricNormalEstimation<PointInT, PointOutT>::computeWithCurvatures(
    PointCloudOut& normals, CurvatureCloud& curvatures) {
  curvatures_ =
      &curvatures;  // filled (not reallocated, when the size is unchanged) by computeFeature
  try {
    this->compute(normals);
  } catch (...) {
    curvatures_ = nullptr;
    throw;
  }
  curvatures_ = nullptr;
  if (curvatures.size() != normals.size()) curvatures.clear();  // compute() failed
  curvatures.header = normals.header;
}

template <typename PointInT, typename PointOutT>
void QuadricNormalEstimation<PointInT, PointOutT>::computeFeature(PointCloudOut& output) {
  using Outcome = typename LocalFitEstimation<PointInT, PointOutT>::FitOutcome;
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  if (curvatures_) {
    pcl::PrincipalCurvatures missing;
    missing.principal_curvature_x = missing.principal_curvature_y = missing.principal_curvature_z =
        nan;
    missing.pc1 = missing.pc2 = nan;
    curvatures_->assign(output.size(), missing);
    curvatures_->width = output.width;
    curvatures_->height = output.height;
  }
  this->fitEachNeighbourhood(
      output, [&](const Eigen::Matrix3Xd& neighbours, int count, const pcl::Indices&,
                  pcl::index_t index, const Eigen::Vector3d& position, std::size_t i) {
        PointOutT& out = output[i];
        const PlaneFit plane = fitPlane(neighbours, count);
        if (!plane.valid) return Outcome::Failed;
        // The query point is the origin of the neighbours' coordinates.
        QuadricFit quadric = fitQuadric(plane, neighbours, count, Eigen::Vector3d::Zero());
        Eigen::Vector3d normal = quadric.valid ? quadric.normal : plane.normal;
        const bool flipped = this->orient(normal, index, position);
        out.normal_x = static_cast<float>(normal.x());
        out.normal_y = static_cast<float>(normal.y());
        out.normal_z = static_cast<float>(normal.z());
        out.curvature = static_cast<float>(plane.surface_variation);
        if (!quadric.valid) return Outcome::FellBack;
        if (curvatures_) {
          if (flipped) quadric.flip();
          pcl::PrincipalCurvatures& c = (*curvatures_)[i];
          c.principal_curvature_x = static_cast<float>(quadric.direction1.x());
          c.principal_curvature_y = static_cast<float>(quadric.direction1.y());
          c.principal_curvature_z = static_cast<float>(quadric.direction1.z());
          c.pc1 = static_cast<float>(quadric.kappa1);
          c.pc2 = static_cast<float>(quadric.kappa2);
        }
        return Outcome::Fitted;
      });
  // A turned normal turns the shape operator: kappa1, kappa2 become -kappa2, -kappa1, and the
  // direction of the new kappa1 is the old kappa2's, old normal x old direction1.
  this->makeOrientationConsistent(output, [&](std::size_t i) {
    if (!curvatures_) return;
    pcl::PrincipalCurvatures& c = (*curvatures_)[i];
    const Eigen::Vector3f old_normal =
        -Eigen::Vector3f(output[i].normal_x, output[i].normal_y, output[i].normal_z);
    const Eigen::Vector3f direction2 = old_normal.cross(
        Eigen::Vector3f(c.principal_curvature_x, c.principal_curvature_y, c.principal_curvature_z));
    const float pc1 = c.pc1;
    c.pc1 = -c.pc2;
    c.pc2 = -pc1;
    c.principal_curvature_x = direction2.x();
    c.principal_curvature_y = direction2.y();
    c.principal_curvature_z = direction2.z();
  });
}

}  // namespace pcl_ddg

#define PCL_DDG_INSTANTIATE_QuadricNormalEstimation(T, NT) \
  template class pcl_ddg::QuadricNormalEstimation<T, NT>;
