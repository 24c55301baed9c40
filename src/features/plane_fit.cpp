#include "pcl_ddg/features/plane_fit.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace pcl_ddg {

namespace {

/** About the centroid, in two passes; divided by the number of points. */
Eigen::Matrix3d covarianceAbout(const Eigen::Vector3d& centroid, const Eigen::Matrix3Xd& points,
                                int count) {
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d d = points.col(i) - centroid;
    covariance.noalias() += d * d.transpose();
  }
  return covariance / count;
}

}  // namespace

PlaneFit fitPlane(const Eigen::Matrix3Xd& points, int count) {
  if (count < 3) return PlaneFit{};
  const Eigen::Vector3d centroid = points.leftCols(count).rowwise().mean();
  return fitPlane(centroid, covarianceAbout(centroid, points, count));
}

PlaneNormal fitPlaneNormal(const Eigen::Matrix3Xd& points, int count) {
  if (count < 3) return PlaneNormal{};
  const Eigen::Vector3d centroid = points.leftCols(count).rowwise().mean();
  return fitPlaneNormal(covarianceAbout(centroid, points, count));
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

PlaneNormal fitPlaneNormal(const Eigen::Matrix3d& covariance) {
  PlaneNormal result;
  const double scale = covariance.diagonal().maxCoeff();  // >= every |entry| when semi-definite
  if (!(scale > 0.0) || !std::isfinite(scale)) return result;
  // Eigenvalues in closed form (Smith 1961): l = mean + p x of the scaled matrix, with x the
  // roots of x^3 - 3x = 2r, r = det(b) / (2 p^3), b the matrix shifted by its mean eigenvalue.
  const Eigen::Matrix3d a = covariance * (1.0 / scale);
  const double mean = a.trace() / 3.0;
  Eigen::Matrix3d b = a;
  b.diagonal().array() -= mean;
  const double p2 = (b.diagonal().squaredNorm() +
                     2.0 * (b(0, 1) * b(0, 1) + b(0, 2) * b(0, 2) + b(1, 2) * b(1, 2))) /
                    6.0;
  if (!(p2 > 0.0)) return result;  // isotropic (or not finite): no preferred normal
  const double p = std::sqrt(p2);
  // The roots are 2 cos(phi + 2 pi j / 3) with cos(3 phi) = r and phi in [0, pi / 3].
  const double phi = std::acos(std::clamp(b.determinant() / (2.0 * p2 * p), -1.0, 1.0)) / 3.0;
  const double cos_phi = std::cos(phi), sin_phi = std::sqrt(std::max(0.0, 1.0 - cos_phi * cos_phi));
  const double x0 = -cos_phi - std::sqrt(3.0) * sin_phi;  // 2 cos(phi + 2 pi / 3)
  const double l0 = mean + p * x0, l2 = mean + 2.0 * p * cos_phi, l1 = 3.0 * mean - l0 - l2;
  if (!(l1 > 1e-12 * l2)) return result;  // all on one line, as in fitPlane
  // The eigenvector: the longest cross product of two rows of a - l0 I (the best conditioned).
  b.diagonal().array() -= p * x0;
  const Eigen::Vector3d c01 = b.row(0).cross(b.row(1)), c02 = b.row(0).cross(b.row(2)),
                        c12 = b.row(1).cross(b.row(2));
  const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
  const Eigen::Vector3d& best = n01 >= n02 ? (n01 >= n12 ? c01 : c12) : (n02 >= n12 ? c02 : c12);
  const double norm = std::sqrt(std::max({n01, n02, n12}));
  if (!(norm > 0.0)) return result;
  result.normal = best / norm;
  result.surface_variation = std::max(0.0, l0) / (3.0 * mean);
  result.valid = result.normal.allFinite();
  return result;
}

}  // namespace pcl_ddg
