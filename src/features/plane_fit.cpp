#include "pcl_ddg/features/plane_fit.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "vector_lanes.h"

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
  // All points on one line (or one point): no plane. Measured as the variance off the principal
  // line, trace - l2 = l0 + l1: the largest eigenvalue is accurate to rounding, while the closed
  // form's l1 is off by about sqrt(eps) l2 when l0 = l1 = 0 (a double root), which let a quarter
  // of random lines rounded to double through as planes.
  if (!(covariance.trace() - fit.eigenvalues[2] > 1e-12 * fit.eigenvalues[2])) return fit;
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
  if (!(l0 + l1 > 1e-12 * l2)) return result;  // all on one line, as in fitPlane
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

namespace {

constexpr int kLanes = 64;
// From 0, Newton's error falls as e <- e^2 r / (1 - r) in units of l0 after a first step to r =
// l0 / l1: 12 steps reach rounding for r up to about 0.6; flatter neighbourhoods need 4 to 7.
constexpr int kNewtonSteps = 12;

PCL_DDG_WIDE_LANES void fitInLanes(int count, const CovarianceArrays& in,
                                   const PlaneNormalArrays& out) {
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  for (int begin = 0; begin < count; begin += kLanes) {
    const int lanes = std::min(kLanes, count - begin);
    // As in fitPlaneNormal: the matrix scaled to a largest diagonal entry of 1, then shifted by its
    // mean eigenvalue to b, whose small entries keep the polynomial well conditioned when the
    // eigenvalues lie close together. Its characteristic polynomial q(t) = t^3 - beta1 t - beta0
    // is negative, rising and concave left of its smallest root t0 = l0 - mean.
    double b00[kLanes], b01[kLanes], b02[kLanes], b11[kLanes], b12[kLanes], b22[kLanes];
    double mean[kLanes], beta1[kLanes], beta0[kLanes], t[kLanes];
    // Flags of 64 bits (1 or 0): the compiler vectorises a loop only if its lanes are of one width.
    double usable[kLanes];
    std::int64_t pending[kLanes];
    const double *xx_in = in.xx + begin, *xy_in = in.xy + begin, *xz_in = in.xz + begin;
    const double *yy_in = in.yy + begin, *yz_in = in.yz + begin, *zz_in = in.zz + begin;
#pragma omp simd
    for (int i = 0; i < lanes; ++i) {
      const double xx = xx_in[i], yy = yy_in[i], zz = zz_in[i];
      const double larger = xx > yy ? xx : yy;
      const double largest = larger > zz ? larger : zz;
      const double inverse =
          largest > 0.0 && largest <= std::numeric_limits<double>::max() ? 1.0 / largest : 0.0;
      mean[i] = (xx + yy + zz) * inverse / 3.0;
      b00[i] = xx * inverse - mean[i], b11[i] = yy * inverse - mean[i];
      b22[i] = zz * inverse - mean[i];
      b01[i] = xy_in[i] * inverse, b02[i] = xz_in[i] * inverse, b12[i] = yz_in[i] * inverse;
      beta1[i] = 0.5 * (b00[i] * b00[i] + b11[i] * b11[i] + b22[i] * b22[i]) + b01[i] * b01[i] +
                 b02[i] * b02[i] + b12[i] * b12[i];
      beta0[i] = b00[i] * (b11[i] * b22[i] - b12[i] * b12[i]) -
                 b01[i] * (b01[i] * b22[i] - b12[i] * b02[i]) +
                 b02[i] * (b01[i] * b12[i] - b11[i] * b02[i]);
      t[i] = -mean[i];  // l = 0
      // Every entry enters beta1 or beta0: both finite means the matrix is.
      usable[i] = inverse > 0.0 && beta1[i] + std::abs(beta0[i]) <= 1e300 ? 1.0 : 0.0;
    }
    for (int i = 0; i < lanes; ++i) pending[i] = usable[i] != 0.0 ? 1 : 0;
    for (int step = 0; step < kNewtonSteps; ++step) {
      std::int64_t still_pending = 0;
#pragma omp simd reduction(+ : still_pending)
      for (int i = 0; i < lanes; ++i) {
        const double q = (t[i] * t[i] - beta1[i]) * t[i] - beta0[i];
        const double rise = -q / (3.0 * t[i] * t[i] - beta1[i]);
        // A step that does not rise by more than rounding is rounding: t0 is reached.
        const bool rising = pending[i] != 0 && rise > 4.0 * kEpsilon * std::abs(t[i]);
        t[i] = rising ? t[i] + rise : t[i];
        pending[i] = rising ? 1 : 0;
        still_pending += pending[i];
      }
      if (still_pending == 0) break;
    }
#pragma omp simd
    for (int i = 0; i < lanes; ++i) {
      const int k = begin + i;
      // The eigenvector: the longest cross product of two rows of b - t0 I, as fitPlaneNormal.
      const double d00 = b00[i] - t[i], d11 = b11[i] - t[i], d22 = b22[i] - t[i];
      const double d01 = b01[i], d02 = b02[i], d12 = b12[i];
      const double c01x = d01 * d12 - d02 * d11, c01y = d02 * d01 - d00 * d12,
                   c01z = d00 * d11 - d01 * d01;
      const double c02x = d01 * d22 - d02 * d12, c02y = d02 * d02 - d00 * d22,
                   c02z = d00 * d12 - d01 * d02;
      const double c12x = d11 * d22 - d12 * d12, c12y = d12 * d02 - d01 * d22,
                   c12z = d01 * d12 - d11 * d02;
      const double n01 = c01x * c01x + c01y * c01y + c01z * c01z;
      const double n02 = c02x * c02x + c02y * c02y + c02z * c02z;
      const double n12 = c12x * c12x + c12y * c12y + c12z * c12z;
      const double n0 = n01 >= n02 ? n01 : n02;
      const double x0 = n01 >= n02 ? c01x : c02x, y0 = n01 >= n02 ? c01y : c02y,
                   z0 = n01 >= n02 ? c01z : c02z;
      const double x = n0 >= n12 ? x0 : c12x, y = n0 >= n12 ? y0 : c12y, z = n0 >= n12 ? z0 : c12z;
      const double norm = std::sqrt(n0 >= n12 ? n0 : n12);
      out.normal_x[k] = x / norm, out.normal_y[k] = y / norm, out.normal_z[k] = z / norm;
      // t1 + t2 = -t0 and t1 t2 = t0^2 - beta1 give l2, for fitPlaneNormal's line test.
      const double l0 = mean[i] + t[i];
      const double discriminant = 4.0 * beta1[i] - 3.0 * t[i] * t[i];
      const double l2 = mean[i] + 0.5 * (std::sqrt(discriminant > 0.0 ? discriminant : 0.0) - t[i]);
      const double l1 = 3.0 * mean[i] - l0 - l2;
      out.surface_variation[k] = (l0 > 0.0 ? l0 : 0.0) / (3.0 * mean[i]);
      usable[i] = usable[i] > 0.0 && norm > 0.0 && l1 > 1e-12 * l2 ? 1.0 : 0.0;
    }
    for (int i = 0; i < lanes; ++i) {
      const int k = begin + i;
      out.valid[k] = usable[i] > 0.0 ? 1 : 0;
      if (pending[i] == 0) continue;
      Eigen::Matrix3d covariance;
      covariance << in.xx[k], in.xy[k], in.xz[k], in.xy[k], in.yy[k], in.yz[k], in.xz[k], in.yz[k],
          in.zz[k];
      const PlaneNormal plane = fitPlaneNormal(covariance);
      out.normal_x[k] = plane.normal.x(), out.normal_y[k] = plane.normal.y();
      out.normal_z[k] = plane.normal.z(), out.surface_variation[k] = plane.surface_variation;
      out.valid[k] = plane.valid ? 1 : 0;
    }
  }
}

}  // namespace

void fitPlaneNormals(int count, const CovarianceArrays& covariances,
                     const PlaneNormalArrays& planes) {
  fitInLanes(count, covariances, planes);
}

}  // namespace pcl_ddg
