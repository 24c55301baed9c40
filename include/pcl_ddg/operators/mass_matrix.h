#pragma once
/** \file
 * Lumped (diagonal) mass matrices: the area each vertex stands for.
 *
 *  Barycentric   one third of every incident triangle. Always positive, but not a consistent
 *                 area: curvature densities over it do not converge (docs/accuracy.md).
 *  Voronoi        circumcentric cells, (|e_ij|^2 cot(k) + |e_ik|^2 cot(j)) / 8 per corner i.
 *                 NEGATIVE contributions on obtuse triangles; exact for well-centred meshes.
 *  MixedVoronoi   Meyer, Desbrun, Schroeder and Barr 2003: Voronoi on non-obtuse triangles;
 *                 an obtuse triangle gives half its area to the obtuse corner and a quarter to
 *                 each other. Always non-negative; the default.
 * For every type the masses sum to the total area of the mesh. Isolated vertices and vertices
 * of degenerate triangles only get zero mass.
 */
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"
#include "pcl_ddg/option_style.h"

namespace pcl_ddg {

enum class MassType { Barycentric, Voronoi, MixedVoronoi };

/** mixed | voronoi | barycentric, as option (the tools' -area, Python's mass=) names them. */
inline MassType chooseMassType(const std::string& name, const std::string& option,
                               const OptionStyle& style) {
  return chooseNamed<MassType>(option, name,
                               {{"mixed", MassType::MixedVoronoi},
                                {"voronoi", MassType::Voronoi},
                                {"barycentric", MassType::Barycentric}},
                               style);
}

/** Vertex areas (the diagonal of M), gathered per vertex (OpenMP). Throws InvalidMeshException
 *  on non-finite or mismatched positions. */
Eigen::VectorXd lumpedMass(const MeshTopology& topology, const PositionsRef& positions,
                           MassType type = MassType::MixedVoronoi);

/** The diagonal mass matrix as a sparse matrix. */
Eigen::SparseMatrix<double> massMatrix(const MeshTopology& topology, const PositionsRef& positions,
                                       MassType type = MassType::MixedVoronoi);

}  // namespace pcl_ddg
