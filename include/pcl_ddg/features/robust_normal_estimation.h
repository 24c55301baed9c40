#pragma once
/** \file
 * Normals that choose their own scale and keep sharp edges: a robust plane (robust_plane_fit.h:
 * the scale by an F-test of plane against quadric, least median of squares over nested-scale and
 * through-the-point planes, a trimmed refit) over each point's k nearest neighbours; then, with
 * a k-nearest search (not a radius), where that plane's neighbourhood is noise, a wider plane
 * summed along the 32-nearest-neighbour graph (widening_planes.h) while its residual stays noise.
 *
 *   pcl_ddg::RobustNormalEstimation<pcl::PointXYZ, pcl::Normal> robust;
 *   robust.setInputCloud(cloud);
 *   robust.setSearchMethod(search);  // pcl::search::KdTree or pcl_ddg::MeshRingSearch
 *   robust.compute(normals);         // k = kRobustNormalNeighbours unless setKSearch/-Radius
 *   robust.getScales();              // per output point: neighbours used
 *
 * Output: normal_x/y/z (unit, oriented as the other estimators: local_fit_estimation.h) and
 * curvature = the surface variation of the robust plane (also where a wider plane gave the
 * normal). getScales() and getConfidences() hold, per output point, the neighbours the plane used
 * and their share of the neighbours found (robust_plane_fit.h); for a wider plane of level l its
 * worth, 32 (l + 1) points (its weight spreads over about l + 1 neighbourhoods), at most the
 * surface's, and 1. NaN where the point failed (fewer than 3 finite neighbours, or all on one
 * line). Planes widen only with k >= kWideGraphWidth nearest (not a radius); the graph rows are
 * the first 32 neighbours the search returns (the nearest, for a k-d tree). The wider planes
 * are formed over the whole search surface (every point of it is a node of the graph), also
 * when only some indices are estimated: their cost is the surface's.
 */
#include <cstdint>
#include <vector>

#include "pcl_ddg/features/local_fit_estimation.h"
#include "pcl_ddg/features/widening_planes.h"

namespace pcl_ddg {

/** The neighbourhood searched by default; wider planes reach beyond it where the data are noisy
 *  (bench/bench_normal_accuracy.py: docs/benchmarks.md has the time against a k = 112 plane
 *  fit). */
constexpr int kRobustNormalNeighbours = 96;
/** The nearest-neighbour graph along which wider planes are summed (widening_planes.h). */
constexpr int kWideGraphWidth = 32;
/** Planes widen from a point only where the plane of about the searched size leaves at most this
 *  many times the residual variance of the robust fit's inliers (widening_planes.h): noise there,
 *  not another face or curvature. */
constexpr double kWideResidual = 2.0;

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

  /** Per output point of the last compute(): the neighbours in the final fit (a wider plane:
   *  32 (level + 1)). */
  const std::vector<float>& getScales() const { return scales_; }
  /** Per output point of the last compute(): the robust fit's neighbours over those found, in
   *  [0, 1]; 1 for a wider plane. */
  const std::vector<float>& getConfidences() const { return confidences_; }

  /** The finite points of the whole cloud the surface is part of (a tile's points with their
   *  halo: the cloud's), at most a wider plane's scale; 0 (the default): the surface's. */
  void setCloudPoints(std::int64_t points) { cloud_points_ = points; }
  /** Also reports each output point's reach (getReaches): for fitting a cloud tile by tile
   *  (tile_certificate.h). Off by default: it costs a square root per graph edge and level. */
  void setReportReaches(bool report) { report_reaches_ = report; }
  /**
   * Per output point of the last compute() with setReportReaches: how far from the point, in the
   * surface's float coordinates, its wider planes read (widening_planes.h: every node whose row
   * was read, with that row's ball, lies within it); 0 where no wider plane was tried; infinity
   * where a row had fewer than kWideGraphWidth points. The output of a point equals the one on
   * a larger cloud around the surface where the point's own search and this ball find the same
   * points in both.
   */
  const std::vector<double>& getReaches() const { return reaches_; }

 protected:
  /** Neither setKSearch nor setRadiusSearch: k = kRobustNormalNeighbours. */
  int defaultK() const override { return kRobustNormalNeighbours; }
  void computeFeature(PointCloudOut& output) override;

 private:
  /** Orients normal (for query point index at position) into out's normal fields. */
  void write(PointOutT& out, Eigen::Vector3d normal, pcl::index_t index,
             const Eigen::Vector3d& position) const;
  /** Where the plane of about the searched size is noise and a wider one keeps explaining the
   *  points as noise (widening_planes.h), that plane's normal instead. query_graph: each
   *  query's nearest kWideGraphWidth of the neighbours its fit searched. */
  void widen(PointCloudOut& output, const std::vector<double>& largest_reference,
             NeighbourGraph query_graph);

  std::vector<float> scales_, confidences_;
  std::vector<double> reaches_;
  std::int64_t cloud_points_ = 0;
  bool report_reaches_ = false;
};

}  // namespace pcl_ddg

#ifdef PCL_NO_PRECOMPILE
#include "pcl_ddg/features/impl/robust_normal_estimation.hpp"
#endif
