#pragma once
/** \file
 * Normals that choose their own scale and keep sharp edges: a robust plane (robust_plane_fit.h:
 * the scale by an F-test of plane against quadric, least median of squares over nested-scale and
 * through-the-point planes, a trimmed refit) over each point's k nearest neighbours, k the
 * largest neighbourhood it may use.
 *
 *   pcl_ddg::RobustNormalEstimation<pcl::PointXYZ, pcl::Normal> robust;
 *   robust.setInputCloud(cloud);
 *   robust.setSearchMethod(search);   // pcl::search::KdTree or pcl_ddg::MeshRingSearch
 *   robust.compute(normals);          // k = kRobustNormalNeighbours, or setKSearch /
 * setRadiusSearch robust.getScales();               // per output point: neighbours used
 *
 * Output: normal_x/y/z (unit, oriented as the other estimators: local_fit_estimation.h) and
 * curvature = the surface variation of the final fit. getScales() and getConfidences() hold, per
 * output point, the neighbours the plane used and their share of the neighbours found
 * (robust_plane_fit.h); NaN where the point failed (fewer than 3 finite neighbours, or all on
 * one line).
 */
#include <vector>

#include "pcl_ddg/features/local_fit_estimation.h"

namespace pcl_ddg {

/** The largest neighbourhood by default (bench/bench_normal_accuracy.py: about 3.4x the time of
 *  a k = 112 plane fit, most of it the search for the neighbours). */
constexpr int kRobustNormalNeighbours = 192;

template <typename PointInT, typename PointOutT>
class RobustNormalEstimation : public LocalFitEstimation<PointInT, PointOutT> {
 public:
  using Ptr = std::shared_ptr<RobustNormalEstimation<PointInT, PointOutT>>;
  using ConstPtr = std::shared_ptr<const RobustNormalEstimation<PointInT, PointOutT>>;
  using PointCloudOut = typename LocalFitEstimation<PointInT, PointOutT>::PointCloudOut;

  /** nr_threads for compute(), as pcl::NormalEstimationOMP's constructor (0: every core). */
  explicit RobustNormalEstimation(unsigned int nr_threads = 0) {
    this->feature_name_ = "RobustNormalEstimation";
    this->setNumberOfThreads(nr_threads);
  }

  /** Per output point of the last compute(): the neighbours in the final fit. */
  const std::vector<float>& getScales() const { return scales_; }
  /** Per output point of the last compute(): that number over the neighbours found, in [0, 1]. */
  const std::vector<float>& getConfidences() const { return confidences_; }

 protected:
  /** Neither setKSearch nor setRadiusSearch: k = kRobustNormalNeighbours. */
  bool initCompute() override {
    if (this->k_ == 0 && this->search_radius_ == 0.0) this->k_ = kRobustNormalNeighbours;
    return LocalFitEstimation<PointInT, PointOutT>::initCompute();
  }
  void computeFeature(PointCloudOut& output) override;
  void setInvalid(PointOutT& point) const override;

 private:
  std::vector<float> scales_, confidences_;
};

}  // namespace pcl_ddg

#ifdef PCL_NO_PRECOMPILE
#include "pcl_ddg/features/impl/robust_normal_estimation.hpp"
#endif
