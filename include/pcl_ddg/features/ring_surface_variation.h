#pragma once
/** \file
 * PCL's "curvature" for mesh vertices: the surface variation of each vertex with its 1-ring, so
 * that mesh normals written for PCL (pcl::PointNormal) carry the value pcl::NormalEstimation would
 * give with that neighbourhood.
 */
#include <Eigen/Core>

#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

/** lambda0 / (lambda0 + lambda1 + lambda2) of the covariance of each vertex and its neighbours
 *  (0 on a plane, 1/3 for isotropic noise; dimensionless, not a curvature in 1/length). NaN where
 *  the ring has fewer than 3 points or they lie on one line. OpenMP over vertices. */
Eigen::VectorXd ringSurfaceVariation(const MeshTopology& topology,
                                     const Eigen::Matrix3Xd& positions);

}  // namespace pcl_ddg
