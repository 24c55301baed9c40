#pragma once
/** \file
 * Normals and principal curvatures from a quadric height field fitted to each point's
 * neighbours (see quadric_fit.h): second-order accurate where the PCA plane is first-order.
 *
 *   pcl_ddg::QuadricNormalEstimation<pcl::PointXYZ, pcl::Normal> quadric;
 *   quadric.setInputCloud(cloud);
 *   quadric.setSearchMethod(search);   // kd-tree or MeshRingSearch
 *   quadric.setKSearch(20);
 *   quadric.compute(normals);                              // normals only, or
 *   quadric.computeWithCurvatures(normals, curvatures);    // + pcl::PrincipalCurvatures
 *
 * Output normals: normal_x/y/z of the fitted surface at the point, oriented as in
 * local_fit_estimation.h, and curvature = the PCA surface variation (PCL's meaning, so code that
 * thresholds it keeps working). Curvatures, as pcl::PrincipalCurvatures: pc1 = kappa1 >= pc2 =
 * kappa2 in 1/length, signed (positive where the surface bends away from the output normal: +1/r
 * on a sphere with outward normals), principal_curvature_x/y/z = the unit direction of kappa1.
 * This differs from pcl::PrincipalCurvaturesEstimation, whose pc1/pc2 are eigenvalues of the
 * projected normals' covariance: unsigned, dimensionless, and not curvatures.
 *
 * With fewer than 6 neighbours or an ill-conditioned fit (e.g. all neighbours on one conic) the
 * PCA normal is used (counted: getFallbackPoints) and the curvatures are NaN.
 */
#include <pcl/point_types.h>

#include "pcl_ddg/features/local_fit_estimation.h"

namespace pcl_ddg {

template <typename PointInT, typename PointOutT>
class QuadricNormalEstimation : public LocalFitEstimation<PointInT, PointOutT> {
 public:
  using Ptr = std::shared_ptr<QuadricNormalEstimation<PointInT, PointOutT>>;
  using ConstPtr = std::shared_ptr<const QuadricNormalEstimation<PointInT, PointOutT>>;
  using PointCloudOut = typename LocalFitEstimation<PointInT, PointOutT>::PointCloudOut;
  using CurvatureCloud = pcl::PointCloud<pcl::PrincipalCurvatures>;

  /** nr_threads for compute(), as pcl::NormalEstimationOMP's constructor (0: every core). */
  explicit QuadricNormalEstimation(unsigned int nr_threads = 0) {
    this->feature_name_ = "QuadricNormalEstimation";
    this->setNumberOfThreads(nr_threads);
  }

  /** compute(normals), also filling curvatures (one per output point) in the same pass. */
  void computeWithCurvatures(PointCloudOut& normals, CurvatureCloud& curvatures);

  /** Points of the last compute that got the PCA normal instead of the quadric's. */
  std::int64_t getFallbackPoints() const { return this->fallback_points_; }

 protected:
  void computeFeature(PointCloudOut& output) override;

 private:
  CurvatureCloud* curvatures_ = nullptr;  ///< set during computeWithCurvatures only
};

}  // namespace pcl_ddg

#ifdef PCL_NO_PRECOMPILE
#include "pcl_ddg/features/impl/quadric_normal_estimation.hpp"
#endif
