#pragma once
/** \file
 * Discrete curvatures at the vertices of a triangle mesh.
 *
 * Sign convention: with the mesh oriented outward, H > 0 and K > 0 on a sphere (kappa > 0 where
 * the surface bends away from the normal).
 *   Gaussian   angle defect: 2 pi - sum of corner angles at an interior vertex, pi - sum at a
 *              boundary vertex (the geodesic turning of the boundary), so that the integrated
 *              values sum to 2 pi chi (Gauss-Bonnet) on every mesh. As a density, divided by the
 *              vertex area (mixed Voronoi by default; barycentric areas do not converge).
 *   Mean       Hn = -1/2 M^-1 L x with the cotangent L; H = |Hn| signed by the area-weighted
 *              vertex normal. On a boundary vertex Hn carries the boundary's curvature too and
 *              is not a surface curvature.
 *   Principal  kappa_{1,2} = H +- sqrt(max(H^2 - K, 0)); vertices where H^2 < K were clamped.
 * Vertices without area (isolated, or only on degenerate triangles) get NaN and valid = 0. Where
 * the incident face normals cancel (a face and its reversed duplicate) H has no sign: mean,
 * kappa1 and kappa2 are NaN, valid = 0 (counted in unoriented_vertices), K is still given.
 */
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"
#include "pcl_ddg/operators/mass_matrix.h"

namespace pcl_ddg {

/** Integrated Gaussian curvature (angle defect) per vertex; 0 for an isolated vertex. */
Eigen::VectorXd angleDefect(const MeshTopology& topology, const PositionsRef& positions);

/** The mean-curvature normal Hn = -1/2 M^-1 L x (zero at zero-mass vertices). */
Eigen::Matrix3Xd meanCurvatureNormal(const MeshTopology& topology, const PositionsRef& positions,
                                     MassType mass = MassType::MixedVoronoi);

struct VertexCurvatures {
  // Named as the tools' output fields; k1, k2 are pcl::PrincipalCurvatures' pc1, pc2.
  Eigen::VectorXd mean_curvature;   ///< H, signed
  Eigen::VectorXd gauss_curvature;  ///< K density (angle defect / vertex area)
  Eigen::VectorXd k1;               ///< k1 >= k2
  Eigen::VectorXd k2;
  Eigen::VectorXd vertex_area;  ///< the mass used
  std::vector<std::uint8_t> valid;
  std::int64_t clamped_vertices = 0;     ///< H^2 < K: k1 = k2 = H there
  std::int64_t invalid_vertices = 0;     ///< valid == 0, all causes
  std::int64_t unoriented_vertices = 0;  ///< of those, the ones whose face normals cancelled
};

/** All curvatures at once, sharing the triangle quantities (OpenMP over vertices). */
VertexCurvatures computeCurvatures(const MeshTopology& topology, const PositionsRef& positions,
                                   MassType mass = MassType::MixedVoronoi);

}  // namespace pcl_ddg
