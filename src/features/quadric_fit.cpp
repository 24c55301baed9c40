#include "pcl_ddg/features/quadric_fit.h"

#include <Eigen/Cholesky>
#include <algorithm>
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

  using Vector6d = Eigen::Matrix<double, 6, 1>;
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  // The normal equations of the rows (u^2, uv, v^2, u, v, 1) hold only the 15 moments
  // sum u^a v^b with a + b <= 4, and the right side the 6 moments sum w u^a v^b: accumulating those
  // is a third less work than the 27 products of the rows.
  double m40 = 0, m31 = 0, m22 = 0, m13 = 0, m04 = 0, m30 = 0, m21 = 0, m12 = 0, m03 = 0;
  double m20 = 0, m11 = 0, m02 = 0, m10 = 0, m01 = 0;
  Vector6d right_side = Vector6d::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d uvw = to_local * (points.col(i) - plane.centroid);
    const double u = uvw.x(), v = uvw.y(), w = uvw.z();
    const double uu = u * u, uv = u * v, vv = v * v;
    m40 += uu * uu, m31 += uu * uv, m22 += uu * vv, m13 += uv * vv, m04 += vv * vv;
    m30 += uu * u, m21 += uu * v, m12 += u * vv, m03 += vv * v;
    m20 += uu, m11 += uv, m02 += vv, m10 += u, m01 += v;
    right_side += w * Vector6d(uu, uv, vv, u, v, 1.0);
  }
  Matrix6d normal_matrix;
  normal_matrix << m40, m31, m22, m30, m21, m20,  //
      m31, m22, m13, m21, m12, m11,               //
      m22, m13, m04, m12, m03, m02,               //
      m30, m21, m12, m20, m11, m10,               //
      m21, m12, m03, m11, m02, m01,               //
      m20, m11, m02, m10, m01, count;
  const Eigen::LLT<Eigen::Ref<Matrix6d>> cholesky(normal_matrix);  // in place
  // Points on a conic (e.g. one ring of a regular grid) leave the quadric undetermined; the
  // Cholesky pivots bound the conditioning (coordinates are scaled to O(1), so 1e-10 is relative).
  if (cholesky.info() != Eigen::Success) return fit;
  const Vector6d pivots = cholesky.matrixLLT().diagonal();
  if (!(pivots.minCoeff() > 1e-5 * pivots.maxCoeff())) return fit;
  const Vector6d q = cholesky.solve(right_side);
  if (!q.allFinite()) return fit;

  // Derivatives at the point: first ones are slopes (scale-free), second ones in 1/length.
  const Eigen::Vector3d uvw = to_local * (at - plane.centroid);
  const double fu = 2.0 * q[0] * uvw.x() + q[1] * uvw.y() + q[3];
  const double fv = q[1] * uvw.x() + 2.0 * q[2] * uvw.y() + q[4];
  const double fuu = 2.0 * q[0] / scale, fuv = q[1] / scale, fvv = 2.0 * q[2] / scale;
  const double w = std::sqrt(1.0 + fu * fu + fv * fv);
  fit.normal = (plane.normal - fu * plane.tangent1 - fv * plane.tangent2) / w;

  // Shape operator S = I^-1 II of the graph, in closed form: its eigenvalues are H +- sqrt(H^2 - K)
  // with K = det II / det I and 2H = trace(S); they bend towards +normal when positive, so they are
  // negated for the convention "positive bends away from the normal".
  const double e = 1.0 + fu * fu, f = fu * fv, g = 1.0 + fv * fv;  // first fundamental form
  const double l = fuu / w, m = fuv / w, n = fvv / w;              // second
  const double det_first = e * g - f * f;
  const double mean = (e * n - 2.0 * f * m + g * l) / (2.0 * det_first);
  const double gauss = (l * n - m * m) / det_first;
  const double root = std::sqrt(std::max(mean * mean - gauss, 0.0));
  const double lowest = mean - root;  // becomes kappa1 after negation
  fit.kappa1 = -lowest;
  fit.kappa2 = -(mean + root);
  // Its eigenvector: (II - lowest I) a = 0, from the row with more weight (either row is zero at an
  // umbilic, where any tangent is principal).
  const Eigen::Vector2d from_first(-(m - lowest * f), l - lowest * e);
  const Eigen::Vector2d from_second(n - lowest * g, -(m - lowest * f));
  Eigen::Vector2d a =
      from_first.squaredNorm() >= from_second.squaredNorm() ? from_first : from_second;
  if (!(a.squaredNorm() > 0.0)) a = Eigen::Vector2d(1.0, 0.0);
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
