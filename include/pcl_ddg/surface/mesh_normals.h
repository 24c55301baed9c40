#pragma once
/** \file
 * Per-vertex normals of a triangle mesh, oriented like its faces (input winding).
 *
 *  Uniform        average of the unit normals of the incident triangles (every face counts the
 *                 same, whatever its size).
 *  Area           sum of the triangles' area vectors: large faces weigh more. Exact for the
 *                 gradient of the enclosed volume; the usual default.
 *  Angle          unit face normals weighted by the corner angle at the vertex (Thuermer and
 *                 Wuethrich 1998): independent of how a flat region is triangulated.
 *  MeanCurvature  direction of the mean-curvature normal -M^-1 L x (cotangent Laplacian), turned
 *                 to agree with the area normal. Where |M^-1 L x| (= 2|H|) is below epsilon the
 *                 surface is locally flat, that direction is noise, and the area normal is used
 *                 (counted in fallback_vertices), as on boundary vertices, where -M^-1 L x
 *                 also holds the curvature of the boundary curve. Default epsilon: 0.02 / mean edge
 *                 length, i.e. radii of curvature above 100 mean edge lengths count as flat.
 * Degenerate triangles contribute nothing. Vertices with no non-degenerate triangle (isolated
 * ones included) get a NaN normal and valid = 0; so do vertices whose weighted face normals
 * cancel (a face and its reversed duplicate), where any direction would be rounding noise
 * (counted in cancelled_vertices).
 */
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"
#include "pcl_ddg/operators/mass_matrix.h"
#include "pcl_ddg/option_style.h"

namespace pcl_ddg {

enum class NormalWeighting { Uniform, Area, Angle, MeanCurvature };

/** area | uniform | angle | mean_curvature, as option (the tools' -method, Python's weights=)
 *  names them. */
inline NormalWeighting chooseNormalWeighting(const std::string& name, const std::string& option,
                                             const OptionStyle& style) {
  return chooseNamed<NormalWeighting>(option, name,
                                      {{"area", NormalWeighting::Area},
                                       {"uniform", NormalWeighting::Uniform},
                                       {"angle", NormalWeighting::Angle},
                                       {"mean_curvature", NormalWeighting::MeanCurvature}},
                                      style);
}

struct MeshNormalOptions {
  NormalWeighting weighting = NormalWeighting::Area;
  /** Threshold on |M^-1 L x| in 1/length; negative means the default 0.02 / mean edge length. */
  double epsilon = -1.0;
  MassType mass = MassType::MixedVoronoi;
};

struct MeshNormals {
  Eigen::Matrix3Xd normals;  ///< unit, or NaN where valid == 0
  std::vector<std::uint8_t> valid;
  std::int64_t invalid_vertices = 0;    ///< NaN normals, all causes
  std::int64_t cancelled_vertices = 0;  ///< of those, the ones whose face normals cancelled
  std::int64_t fallback_vertices = 0;   ///< MeanCurvature: flat vertices given the area normal
};

MeshNormals computeMeshNormals(const MeshTopology& topology, const PositionsRef& positions,
                               const MeshNormalOptions& options = {});

}  // namespace pcl_ddg
