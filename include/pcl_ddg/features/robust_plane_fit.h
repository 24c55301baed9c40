#pragma once
/** \file
 * A plane fitted to one neighbourhood that chooses its own scale and does not average across a
 * sharp edge. The neighbourhood is the query point q and its k nearest neighbours x_i (relative
 * to q, nearest first); k is the largest scale it may use.
 *
 * 1. **Nested planes.** The least-squares planes of the 16, 24, 32, 48, 64, 96, ... nearest and of
 *    all k (prefix sums of the moments), each through the centroid of the 8 nearest (near the
 *    surface: a large plane through its own centroid lies off a curved surface), with its
 *    residual variance \f$ \lambda_0 \f$ (smallest covariance eigenvalue).
 * 2. **Scale** (in the spirit of Mitra and Nguyen 2003): the largest scale m at which the plane
 *    explains the neighbours nearly as well as the height-field quadric
 *    \f$ w = a u^2 + b uv + c v^2 + d u + e v + f \f$ does (an F-test of the nested models):
 *    \f[ \lambda_0 \frac{m}{m - 3} \le 2\, \max\left(\frac{\mathrm{SSR}_{quadric}}{m - 6},
 *        (10^{-6} r)^2\right), \f]
 *    r the neighbourhood's radius. There the plane's residual is noise, not curvature or an edge,
 *    and more neighbours only average the noise: clean curved data keeps the smallest scale,
 *    noisy data nearly flat at that size all k.
 * 3. **Least median of squares** (Rousseeuw 1984) over the nearest min(m, 64): the nested planes
 *    up to m; and, where the neighbourhood is neither smooth (at the smallest scale the quadric
 *    leaves less than 1 % of the plane's residual variance) nor one plane up to the largest
 *    scale, also the planes through q and two of its 6 nearest neighbours, which win if they
 *    halve the median: a point on one face of an edge spans its own face with its nearest
 *    neighbours there, which hold most of any ball about it. (Where no quadric can be fitted,
 *    the plane counts as not explained.)
 * 4. **Trimmed refit.** \f$ \hat\sigma = 1.4826\, \mathrm{med}_i |r_i| \f$ (the standard
 *    deviation for Gaussian residuals), floored at \f$ 10^{-6} r \f$; the least-squares plane of
 *    the m nearest within \f$ 3 \hat\sigma \f$ of the plane, repeated (at most 5 times) until the
 *    normal turns less than 1e-5 rad: the other face of an edge and outliers drop out.
 *
 * Per point it reports the scale used (the neighbours in the final fit) and a confidence: that
 * number over the neighbours found (k). It is near 1 where one plane explains the whole
 * neighbourhood (flat parts, or noise that hides the curvature) and small where the fit had to
 * stay local: clean curved parts (about 16 / k), edges and corners. Deterministic: the same
 * neighbours give the same bits on any thread.
 */
#include <Eigen/Core>

namespace pcl_ddg {

struct RobustPlaneFit {
  bool valid = false;              ///< 3 neighbours not on one line
  Eigen::Vector3d normal;          ///< unit (sign arbitrary)
  Eigen::Vector3d centroid;        ///< of the final fit, in the coordinates of the points
  double surface_variation = 0.0;  ///< l0 / (l0 + l1 + l2) of the final fit's covariance
  int scale = 0;                   ///< neighbours in the final fit
  double confidence = 0.0;         ///< scale / neighbours found, in [0, 1]
  double noise = 0.0;              ///< sigma-hat, the robust residual scale (length)
  /** The final fit's residual variance (length^2), lambda0 m / (m - 3) over its m points (a plane
   * takes 3 degrees of freedom): the noise variance where its plane is the surface. */
  double residual = 0.0;
};

/** The robust plane of the first count columns of points, given relative to the query point
 *  (which is the origin; it may be among them), in any order: they are taken nearest first (read
 *  in place when they come so, as from a k-d tree; ties keep their order). Invalid below 3 points
 *  or on one line. */
RobustPlaneFit fitRobustPlane(const Eigen::Matrix3Xd& points, int count);

}  // namespace pcl_ddg
