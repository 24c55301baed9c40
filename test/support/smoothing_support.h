#pragma once
// Shared pieces of the smoothing tests: the mesh's time unit, and forward and backward Euler on
// the reference operator (reference_operators.h), independent of the library's operators and
// solvers.
#include <Eigen/Core>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/operators/mass_matrix.h"

namespace pcl_ddg {
namespace test {

/** h^2, h the mean edge length: the unit of implicit time steps. */
double squaredEdge(const MeshTopology& topology, const Eigen::Matrix3Xd& x);

/** steps of (M - tau L) f' = M f with the reference cotangent L and mass M of x frozen, by
 *  Eigen's SimplicialLLT (not the library's solvers); values N x c, one row per vertex. */
Eigen::MatrixXd referenceBackwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                       const Eigen::MatrixXd& values, double tau, int steps,
                                       MassType mass = MassType::MixedVoronoi);

/** The same for the positions themselves (3 x N like x). */
Eigen::Matrix3Xd frozenBackwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                     double tau, int steps, MassType mass = MassType::MixedVoronoi);

/** steps of x <- x + tau M^-1 L x with the reference operator of the input frozen (every vertex
 *  has mass). */
Eigen::Matrix3Xd frozenForwardEuler(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                                    double tau, int steps);

}  // namespace test
}  // namespace pcl_ddg
