#pragma once
/** \file
 * Normals by a least-squares plane through each point's neighbours, as pcl::NormalEstimation,
 * but with the covariance accumulated in double about the neighbourhood (PCL's is in float about
 * the world origin, which costs degrees of accuracy 1e5 from it) and oriented by the mesh's faces
 * when the neighbourhoods come from a MeshRingSearch (see local_fit_estimation.h).
 *
 *   pcl_ddg::PCANormalEstimation<pcl::PointXYZ, pcl::Normal> pca;
 *   pca.setInputCloud(cloud);
 *   pca.setSearchMethod(search);   // pcl::search::KdTree or pcl_ddg::MeshRingSearch
 *   pca.setKSearch(16);            // or setRadiusSearch(r)
 *   pca.compute(normals);
 *
 * Output: normal_x/y/z (unit) and curvature = surface variation lambda0 / (lambda0 + lambda1 +
 * lambda2) of the covariance eigenvalues, PCL's meaning (not a curvature in 1/length). Needs 3
 * finite neighbours not on one line; otherwise NaN (counted).
 */
#include "pcl_ddg/features/local_fit_estimation.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
class PCANormalEstimation : public LocalFitEstimation<PointInT, PointOutT> {
 public:
  using Ptr = std::shared_ptr<PCANormalEstimation<PointInT, PointOutT>>;
  using ConstPtr = std::shared_ptr<const PCANormalEstimation<PointInT, PointOutT>>;
  using PointCloudOut = typename LocalFitEstimation<PointInT, PointOutT>::PointCloudOut;

  /** nr_threads for compute(), as pcl::NormalEstimationOMP's constructor (0: every core). */
  explicit PCANormalEstimation(unsigned int nr_threads = 0) {
    this->feature_name_ = "PCANormalEstimation";
    this->setNumberOfThreads(nr_threads);
  }

 protected:
  void computeFeature(PointCloudOut& output) override;
};

}  // namespace pcl_ddg

#ifdef PCL_NO_PRECOMPILE
#include "pcl_ddg/features/impl/pca_normal_estimation.hpp"
#endif
