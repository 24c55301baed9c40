#pragma once
/** \file
 * A plane fitted to one neighbourhood that chooses its own scale and does not average across a
 * sharp edge: the robust statistics of Fleishman et al. 2005 and Li et al. 2010 (least median
 * of squares, then a reweighted fit) on a plain k-nearest neighbourhood.
 *
 * The neighbourhood is the query point q and its K nearest neighbours x_i (relative to q).
 *
 * 1. **Hypotheses.** The least-squares planes (PCA) of the 8, 16, 32, ... nearest and of all K
 *    (nested scales: prefix sums of the neighbours sorted by distance), and the planes through q
 *    and two of its 8 nearest neighbours (a point on a face of an edge spans its own face with
 *    its nearest neighbours on that face).
 * 2. **Selection by least median of squares** (Rousseeuw 1984): the hypothesis (n, c) whose
 *    median residual \f$ \mathrm{med}_i |n \cdot (x_i - c)| \f$ over all K is smallest. A plane
 *    that explains at least half of the neighbourhood wins: the face the point lies on (it holds
 *    more than half of any ball about a point on it), not the average of two faces.
 * 3. **Noise scale** \f$ \hat\sigma = 1.4826\, \mathrm{med}_i |r_i| \f$ of that plane (the
 *    residual's standard deviation for Gaussian noise), with a floor of 1e-6 of the
 *    neighbourhood's radius for noise-free data.
 * 4. **Reweighted fit** (iteratively reweighted least squares): Tukey's biweight
 *    \f$ w_i = (1 - (r_i / b)^2)^2 \f$ for \f$ |r_i| < b = 4.685\,\hat\sigma \f$ (95 % efficiency
 *    under Gaussian noise), else 0; the weighted centroid and covariance give the next plane;
 *    until the normal stops turning. The band b chooses the scale: neighbours farther from the
 *    plane than the noise explains (the other face, a curved surface's far points) get no
 *    weight, so on noisy data all K count and on clean curved data only those within the
 *    curvature's own deviation.
 *
 * Per point it reports the scale used (neighbours with a weight) and a confidence: the mean
 * weight over the K neighbours (near 0.9 for Gaussian noise on a plane, about half at an edge,
 * low where no plane explains the neighbourhood).
 */
#include <Eigen/Core>

namespace pcl_ddg {

struct RobustPlaneFit {
  bool valid = false;              ///< 3 neighbours not on one line
  Eigen::Vector3d normal;          ///< unit (sign arbitrary)
  Eigen::Vector3d centroid;        ///< weighted, in the coordinates of the points
  double surface_variation = 0.0;  ///< l0 / (l0 + l1 + l2) of the weighted covariance
  int scale = 0;                   ///< neighbours with a nonzero weight
  double confidence = 0.0;         ///< sum of the weights / neighbours, in [0, 1]
  double noise = 0.0;              ///< sigma-hat, the robust residual scale (length)
};

/** The robust plane of the first count columns of points, given relative to the query point
 *  (which is the origin; it may be among them). Invalid below 3 points or on one line. */
RobustPlaneFit fitRobustPlane(const Eigen::Matrix3Xd& points, int count);

}  // namespace pcl_ddg
