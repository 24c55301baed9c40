#pragma once
/** \file
 * Smoothing of organized clouds and depth images: the heat equation on the image grid with the
 * 5-point stencil, applied to each point's range along its viewing ray (so points only move
 * along their rays and the image stays a valid projection).
 *
 * With r the distance of a pixel's point from the sensor origin and tau the time step in
 * pixel^2 units:
 *   explicit  r <- r + tau L r          (stable for tau < 1/4: L's eigenvalues lie in [-8, 0])
 *   implicit  (I - tau L) r' = r        (stable for any tau; one factorisation for all steps, or
 *                                        conjugate gradients: implicit_solver.h)
 * where (L r)_i = sum over coupled 4-neighbours j of (r_j - r_i). Pixels with a non-finite point
 * are holes: missing data, never coupled, never filled; they stay NaN. A point exactly at the
 * sensor origin has no ray: it is not coupled and kept as it is. With no valid pixel at all the
 * result equals the input. Two
 * neighbours are not coupled across a depth jump: |r_i - r_j| > max_depth_jump * min(r_i, r_j)
 * (relative, so the same threshold works at every distance), decided once on the input. The grid
 * border is insulated (no flux), so a constant range is kept exactly.
 */
#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include "pcl_ddg/operators/sparse_cholesky.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {

struct GridSmoothingParameters {
  SmoothingScheme scheme = SmoothingScheme::Implicit;
  double time_step = 1.0;  ///< tau, pixel^2
  int iterations = 1;
  double max_depth_jump = 0.05;  ///< relative range difference above which pixels decouple
  ImplicitSolver implicit_solver = ImplicitSolver::Automatic;
  CholeskyBackend solver = CholeskyBackend::Automatic;  ///< when the implicit solver factorises
};

struct GridSmoothingReport {
  std::int64_t valid_pixels = 0;
  std::int64_t holes = 0;
  std::int64_t points_at_origin = 0;  ///< kept in place (no ray to move along)
  std::int64_t coupled_pairs = 0;
  std::int64_t cut_pairs = 0;  ///< neighbours both valid but across a depth jump
};

/**
 * Smooths positions (3 x width*height, row-major image order as in pcl::PointCloud) of an
 * organized cloud seen from origin. Throws pcl::BadArgumentException on a size mismatch, a grid
 * that is not organized (height < 2), or bad parameters; pcl::ComputeFailedException if an
 * explicit step blows up (naming it).
 */
Eigen::Matrix3Xd smoothOrganizedPositions(const Eigen::Matrix3Xd& positions, int width, int height,
                                          const Eigen::Vector3d& origin,
                                          const GridSmoothingParameters& parameters,
                                          GridSmoothingReport* report = nullptr);

/** The same on a pcl::PointCloud (from its sensor_origin_); other fields are copied. */
template <typename PointT>
void smoothOrganizedCloud(const pcl::PointCloud<PointT>& input, pcl::PointCloud<PointT>& output,
                          const GridSmoothingParameters& parameters,
                          GridSmoothingReport* report = nullptr) {
  Eigen::Matrix3Xd positions(3, static_cast<Eigen::Index>(input.size()));
  for (std::size_t i = 0; i < input.size(); ++i) {
    positions.col(i) = input[i].getVector3fMap().template cast<double>();
  }
  const Eigen::Matrix3Xd smoothed = smoothOrganizedPositions(
      positions, static_cast<int>(input.width), static_cast<int>(input.height),
      input.sensor_origin_.template head<3>().template cast<double>(), parameters, report);
  pcl::PointCloud<PointT> result = input;
  for (std::size_t i = 0; i < result.size(); ++i) {
    result[i].getVector3fMap() = smoothed.col(i).template cast<float>();
  }
  output = std::move(result);
}

}  // namespace pcl_ddg
