#pragma once
/** \file
 * Discrete Laplace-Beltrami operators on a triangle mesh.
 *
 * Convention: L is NEGATIVE semi-definite. Off-diagonal L_ij = w_ij for every mesh edge ij, the
 * diagonal L_ii = -sum_j w_ij, so L * 1 = 0 and (L x)_i = sum_j w_ij (x_j - x_i).
 *   Uniform (umbrella)  w_ij = 1 (diagonal -|N(i)|), purely topological.
 *   Cotangent           w_ij = (cot a_ij + cot b_ij) / 2 over the angles opposite edge ij; a
 *                       boundary edge has one cotangent, a non-manifold edge one per triangle.
 *                       Exact on linear functions over planar meshes (linear precision).
 * Forms:
 *   Summed    L itself: symmetric (the weak / stiffness form used with a mass matrix).
 *   Averaged  M^-1 L (a pointwise Laplacian, M a lumped mass matrix): for the cotangent weights
 *             M^-1 L x approximates the Laplace-Beltrami of the coordinates, -2 H n. Rows of
 *             zero-mass vertices (isolated, or only on degenerate triangles) are zero.
 * Degenerate (zero-area) triangles contribute no weight; isolated vertices have an empty row.
 */
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"
#include "pcl_ddg/operators/mass_matrix.h"

namespace pcl_ddg {

enum class LaplacianWeights { Uniform, Cotangent };
enum class LaplacianForm { Summed, Averaged };

/**
 * Assembles L (pattern: the mesh graph plus the diagonal, built straight into compressed storage;
 * OpenMP over vertices). Throws InvalidMeshException on non-finite or mismatched positions.
 *
 * The summed L equals its transpose bit for bit (both ends of an edge add the same cotangents in
 * the same order), so its compressed columns are its compressed rows.
 * \tparam Storage Eigen::ColMajor (compressed columns, Eigen's default) or Eigen::RowMajor
 *         (compressed rows, scipy's CSR): the same matrix, bit for bit, without a transposition.
 */
template <int Storage = Eigen::ColMajor>
Eigen::SparseMatrix<double, Storage> laplacian(
    const MeshTopology& topology, const PositionsRef& positions,
    LaplacianWeights weights = LaplacianWeights::Cotangent,
    LaplacianForm form = LaplacianForm::Summed, MassType mass = MassType::MixedVoronoi);
extern template Eigen::SparseMatrix<double, Eigen::ColMajor> laplacian<Eigen::ColMajor>(
    const MeshTopology&, const PositionsRef&, LaplacianWeights, LaplacianForm, MassType);
extern template Eigen::SparseMatrix<double, Eigen::RowMajor> laplacian<Eigen::RowMajor>(
    const MeshTopology&, const PositionsRef&, LaplacianWeights, LaplacianForm, MassType);

/** The summed cotangent Laplacian. */
Eigen::SparseMatrix<double> cotangentLaplacian(const MeshTopology& topology,
                                               const PositionsRef& positions);

}  // namespace pcl_ddg
