#pragma once
/** \file
 * Least-squares plane through a neighbourhood: the PCA of its points.
 */
#include <Eigen/Core>
#include <cstdint>

namespace pcl_ddg {

struct PlaneFit {
  bool valid = false;        ///< at least 3 points, not all on one line
  Eigen::Vector3d centroid;  ///< in the coordinates of the input points
  Eigen::Vector3d normal;    ///< unit eigenvector of the smallest eigenvalue (sign arbitrary)
  Eigen::Vector3d tangent1;  ///< largest eigenvalue's eigenvector
  Eigen::Vector3d tangent2;  ///< normal x tangent1, so (tangent1, tangent2, normal) is right-handed
  Eigen::Vector3d eigenvalues;  ///< of the covariance, ascending
  /** Surface variation lambda0 / (lambda0 + lambda1 + lambda2), PCL's "curvature" (0 on a plane,
   *  1/3 for isotropic noise; not a curvature in 1/length). */
  double surface_variation = 0.0;
};

/** Fits a plane to the first count columns of points. The covariance is formed in double about the
 *  centroid (two passes), so points far from the origin lose nothing; pass them relative to a
 *  nearby origin (e.g. the query point) when they come from float coordinates. */
PlaneFit fitPlane(const Eigen::Matrix3Xd& points, int count);

/** The plane of a neighbourhood given by its centroid and covariance (about the centroid, divided
 *  by the number of points): how window sums (window_sums.h) are turned into a plane. */
PlaneFit fitPlane(const Eigen::Vector3d& centroid, const Eigen::Matrix3d& covariance);

/** Only the normal and the surface variation of a plane fit, for per-pixel fits at frame rate. */
struct PlaneNormal {
  bool valid = false;  ///< as PlaneFit::valid
  Eigen::Vector3d normal;
  double surface_variation = 0.0;
};

/** The smallest eigenpair of a covariance (about the centroid, divided by the number of points):
 *  the eigenvalues in closed form, then only the smallest one's eigenvector, as the
 *  best-conditioned cross product of rows of A - lambda0 I. fitPlane's normal and surface
 *  variation up to rounding (both closed forms are good to rounding * (l2 / (l1 - l0))^2 in the
 *  normal), at half the cost: the solver behind fitPlane also finds the other two eigenvectors.
 *  Unlike fitPlane, an isotropic covariance (no preferred direction) is not valid. */
PlaneNormal fitPlaneNormal(const Eigen::Matrix3d& covariance);

/** fitPlaneNormal of the first count columns of points, their covariance formed as in fitPlane. */
PlaneNormal fitPlaneNormal(const Eigen::Matrix3Xd& points, int count);

/** Many covariances side by side, one array per entry (structure of arrays). */
struct CovarianceArrays {
  const double *xx, *xy, *xz, *yy, *yz, *zz;
};

/** Where fitPlaneNormals writes: one array per component; valid[i] is 0 or 1. */
struct PlaneNormalArrays {
  double *normal_x, *normal_y, *normal_z, *surface_variation;
  std::uint8_t* valid;
};

/** fitPlaneNormal of covariances 0 .. count - 1, equal to it up to rounding, several at once in
 *  the CPU's vector lanes: the smallest eigenvalue by Newton's method on the characteristic
 *  polynomial from 0, which rises monotonically to it without trigonometry. The few covariances
 *  where it has not converged within a fixed number of steps (l0 close to l1: nearly isotropic
 *  neighbourhoods, never good planes) go to fitPlaneNormal. */
void fitPlaneNormals(int count, const CovarianceArrays& covariances,
                     const PlaneNormalArrays& planes);

}  // namespace pcl_ddg
