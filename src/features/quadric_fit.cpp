#include "pcl_ddg/features/quadric_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <utility>

namespace pcl_ddg {

QuadricFit fitQuadric(const PlaneFit& plane, const Eigen::Matrix3Xd& points, int count,
                      const Eigen::Vector3d& at) {
  QuadricFit fit;
  if (!plane.valid || count < 6) return fit;
  // Coordinates in units of the neighbourhood's in-plane spread keep the 6 x 6 normal equations
  // well conditioned whatever the scan's scale.
  const double scale = std::sqrt(plane.eigenvalues[1] + plane.eigenvalues[2]);
  Eigen::Matrix3d to_local;
  to_local << plane.tangent1.transpose(), plane.tangent2.transpose(), plane.normal.transpose();
  to_local /= scale;

  Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> right_side = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d uvw = to_local * (points.col(i) - plane.centroid);
    Eigen::Matrix<double, 6, 1> row;
    row << uvw.x() * uvw.x(), uvw.x() * uvw.y(), uvw.y() * uvw.y(), uvw.x(), uvw.y(), 1.0;
    normal_matrix.selfadjointView<Eigen::Lower>().rankUpdate(row);
    right_side += uvw.z() * row;
  }
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>, Eigen::Lower> ldlt(normal_matrix);
  // Points on a conic (e.g. one ring of a regular grid) leave the quadric undetermined.
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.rcond() > 1e-10)) return fit;
  const Eigen::Matrix<double, 6, 1> q = ldlt.solve(right_side);
  if (!q.allFinite()) return fit;

  // Derivatives at the point: first ones are slopes (scale-free), second ones in 1/length.
  const Eigen::Vector3d uvw = to_local * (at - plane.centroid);
  const double fu = 2.0 * q[0] * uvw.x() + q[1] * uvw.y() + q[3];
  const double fv = q[1] * uvw.x() + 2.0 * q[2] * uvw.y() + q[4];
  const double fuu = 2.0 * q[0] / scale, fuv = q[1] / scale, fvv = 2.0 * q[2] / scale;
  const double w = std::sqrt(1.0 + fu * fu + fv * fv);
  fit.normal = (plane.normal - fu * plane.tangent1 - fv * plane.tangent2) / w;

  // Shape operator I^-1 II of the graph; its eigenvalues bend towards +normal when positive,
  // so they are negated for the convention "positive bends away from the normal".
  Eigen::Matrix2d first, second;
  first << 1.0 + fu * fu, fu * fv, fu * fv, 1.0 + fv * fv;
  second << fuu, fuv, fuv, fvv;
  second /= w;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> shape(second, first);
  if (shape.info() != Eigen::Success) return fit;
  fit.kappa1 = -shape.eigenvalues()[0];
  fit.kappa2 = -shape.eigenvalues()[1];
  const Eigen::Vector2d a = shape.eigenvectors().col(0);
  const Eigen::Vector3d du = plane.tangent1 + fu * plane.normal,
                        dv = plane.tangent2 + fv * plane.normal;
  fit.direction1 = (a.x() * du + a.y() * dv).normalized();
  fit.direction2 = fit.normal.cross(fit.direction1);
  fit.valid = fit.normal.allFinite() && fit.direction1.allFinite() && std::isfinite(fit.kappa1) &&
              std::isfinite(fit.kappa2);
  return fit;
}

void QuadricFit::flip() {
  normal = -normal;
  const double k1 = kappa1;
  kappa1 = -kappa2;
  kappa2 = -k1;
  std::swap(direction1, direction2);
  direction2 = normal.cross(direction1);
}

}  // namespace pcl_ddg
