#pragma once
/** \file
 * Heat flow of per-vertex scalar fields on a mesh: df/dt = lambda * Laplace-Beltrami(f), e.g. to
 * smooth a noisy curvature before colouring it.
 *
 * With tau = lambda * dt = diffusion_time / iterations per step:
 *   explicit  f <- f + tau M^-1 L f           (stable for tau below a fraction of h^2)
 *   implicit  (M - tau L) f' = M f            (one factorisation for all steps and all fields, or
 *                                              conjugate gradients: implicit_solver.h)
 * L (summed, cotangent or uniform) and M (lumped) are those of the fixed mesh. Both schemes
 * conserve the mass-weighted sum of f on a closed mesh (1^T L = 0); a free boundary is insulated
 * (no flux), a fixed one keeps its values (Dirichlet). diffusion_time is in length^2: after a time
 * t, detail below a wavelength of about sqrt(4 pi^2 t) is gone.
 *
 * Non-finite values are allowed only on vertices without mass (isolated, or only on degenerate
 * triangles), which keep them; anywhere else they raise pcl::BadArgumentException naming the
 * first vertex and the count. Other errors as in mesh_smoothing.h.
 */
#include <Eigen/Core>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {

struct HeatFlowParameters {
  SmoothingScheme scheme = SmoothingScheme::Implicit;
  LaplacianWeights weights = LaplacianWeights::Cotangent;
  MassType mass = MassType::MixedVoronoi;
  double diffusion_time = 0.0;  ///< lambda * t, length^2
  int iterations = 1;
  BoundaryCondition boundary = BoundaryCondition::Free;
  ImplicitSolver implicit_solver = ImplicitSolver::Automatic;
  CholeskyBackend solver = CholeskyBackend::Automatic;  ///< when the implicit solver factorises
};

/** Smooths every column of fields (N x c, one row per vertex). */
Eigen::MatrixXd smoothScalarFields(const MeshTopology& topology, const PositionsRef& positions,
                                   const Eigen::MatrixXd& fields,
                                   const HeatFlowParameters& parameters);

/** One field. */
Eigen::VectorXd smoothScalarField(const MeshTopology& topology, const PositionsRef& positions,
                                  const Eigen::VectorXd& field,
                                  const HeatFlowParameters& parameters);

}  // namespace pcl_ddg
