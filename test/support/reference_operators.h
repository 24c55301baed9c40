#pragma once
// Reference operators for the tests, assembled triangle by triangle from textbook geometry and
// sharing no code with laplacian() or lumpedMass(): the library gathers per vertex through its own
// cotangent and corner-mass helpers; here every triangle scatters its entries, cotangents are
// dot / |cross| from each corner, and Voronoi cells are polygons cut at the circumcentre.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/operators/mass_matrix.h"

namespace pcl_ddg {
namespace test {

/** The summed cotangent Laplacian: L_ij = 1/2 sum of cot of the angles opposite edge ij over the
 *  (non-degenerate) triangles holding it, L_ii = -sum_j L_ij. */
Eigen::SparseMatrix<double> referenceCotangentLaplacian(const MeshTopology& topology,
                                                        const Eigen::Matrix3Xd& x);

/** The part of one triangle's area that belongs to its corner i (0, 1, 2):
 *  Barycentric a third; Voronoi the signed area of the quadrilateral corner, edge midpoints and
 *  circumcentre (negative where the circumcentre lies beyond the opposite side of an obtuse
 *  triangle); MixedVoronoi the same cell on non-obtuse triangles, else half the area to the
 *  obtuse corner and a quarter to each other. */
double referenceCornerArea(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                           const Eigen::Vector3d& p2, int i, MassType type);

/** Per-vertex masses: the corner areas of every non-degenerate triangle summed at its corners. */
Eigen::VectorXd referenceMass(const MeshTopology& topology, const Eigen::Matrix3Xd& x,
                              MassType type = MassType::MixedVoronoi);

}  // namespace test
}  // namespace pcl_ddg
