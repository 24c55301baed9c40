#include "pcl_ddg/features/plane_fit.h"

#include <Eigen/Eigenvalues>

namespace pcl_ddg {

PlaneFit fitPlane(const Eigen::Matrix3Xd& points, int count) {
  if (count < 3) return PlaneFit{};
  const auto neighbourhood = points.leftCols(count);
  const Eigen::Vector3d centroid = neighbourhood.rowwise().mean();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d d = neighbourhood.col(i) - centroid;
    covariance.noalias() += d * d.transpose();
  }
  return fitPlane(centroid, covariance / count);
}

PlaneFit fitPlane(const Eigen::Vector3d& centroid, const Eigen::Matrix3d& covariance) {
  PlaneFit fit;
  fit.centroid = centroid;
  // Closed form for symmetric 3x3 (Eigen scales and trace-shifts the matrix first, and takes the
  // eigenvectors from the best-conditioned cross products of rows of A - lambda I).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  fit.eigenvalues = solver.eigenvalues().cwiseMax(0.0);
  // All points on one line (or one point): no plane.
  if (!(fit.eigenvalues[1] > 1e-12 * fit.eigenvalues[2])) return fit;
  fit.normal = solver.eigenvectors().col(0).normalized();
  fit.tangent1 = solver.eigenvectors().col(2).normalized();
  fit.tangent2 = fit.normal.cross(fit.tangent1);
  fit.surface_variation = fit.eigenvalues[0] / fit.eigenvalues.sum();
  fit.valid = fit.normal.allFinite();
  return fit;
}

}  // namespace pcl_ddg
