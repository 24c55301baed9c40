#pragma once
/** \file
 * Height-field quadric through a neighbourhood, in the frame of its fitted plane:
 *   w = f(u, v) = a u^2 + b uv + c v^2 + d u + e v + g   (least squares over the neighbours),
 * with (u, v, w) the coordinates along (tangent1, tangent2, normal) of the plane fit about its
 * centroid. The normal at a point is that of the graph, (-f_u, -f_v, 1) / |.|, at the point's own
 * (u, v); the principal curvatures are the eigenvalues of the graph's shape operator there.
 */
#include <Eigen/Core>

#include "pcl_ddg/features/plane_fit.h"

namespace pcl_ddg {

struct QuadricFit {
  bool valid = false;      ///< fewer than 6 points or an ill-conditioned system: false
  Eigen::Vector3d normal;  ///< unit, on the side of plane.normal
  /** Principal curvatures (1/length), kappa1 >= kappa2, signed so that they are positive where the
   *  surface bends away from `normal` (a sphere with outward normals has +1/r). */
  double kappa1 = 0.0, kappa2 = 0.0;
  Eigen::Vector3d direction1;  ///< unit principal direction of kappa1, tangent to the fit
  Eigen::Vector3d direction2;  ///< normal x direction1

  /** Turns the normal around: the curvatures change sign and swap (kappa1 >= kappa2 stays). */
  void flip();
};

/** Fits the quadric to the first count columns of points (the same points, in the same
 *  coordinates, as plane), evaluated at `at`. */
QuadricFit fitQuadric(const PlaneFit& plane, const Eigen::Matrix3Xd& points, int count,
                      const Eigen::Vector3d& at);

}  // namespace pcl_ddg
