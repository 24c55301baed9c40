#pragma once
// Shared pieces of the smoothing tests: the mesh's time unit and an independent backward Euler.
#include <Eigen/Core>

#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {
namespace test {

/** h^2, h the mean edge length: the unit of implicit time steps. */
double squaredEdge(const MeshTopology& topology, const Eigen::Matrix3Xd& x);

/** steps of (M - tau L) x' = M x with the cotangent L and mixed mass of x frozen, by Eigen's
 *  SimplicialLLT (not the library's solvers); 3 x N like x. */
Eigen::Matrix3Xd frozenBackwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                     double tau, int steps);

}  // namespace test
}  // namespace pcl_ddg
