#pragma once
/** \file
 * What a user must hear about a result, as one message each: the tools print them, the Python
 * module raises them as `pcl_ddg.PclDdgWarning`, the Dask runner lists them in its summary.
 *
 *  - the coordinates are rounded coarser than half the points' spacing (PointSpacing::quantised):
 *    neighbourhoods tie and normals snap to the lattice;
 *  - the orientation faces a viewpoint more than 10 times the data's extent (the box's diagonal)
 *    from its bounding box: seen from that far, n . (v - p) is nearly the same for every point,
 *    and its sign almost random on aerial data;
 *  - points left without an estimate (NaN), or with a quadric fallen back to a PCA normal;
 *  - mesh vertices without a normal (their face normals cancel: reversed duplicate faces?), or
 *    that took the area normal where the mean-curvature normal is undefined;
 *  - mesh vertices without a curvature (no area; face normals that cancel).
 *
 * (Vertices with H^2 < K, where k1 = k2 = H, are normal on spheres and noise: counted, not
 * warned about.)
 *
 * The remedies name the options as the caller spells them (OptionSpelling).
 */
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/search/point_spacing.h"
#include "pcl_ddg/surface/mesh_normals.h"

namespace pcl_ddg {

/** How the caller's users write the options a remedy names. */
struct OptionSpelling {
  std::string viewpoint = "viewpoint=(x, y, z)";  ///< the sensor position
  std::string orient_up = "orient=\"up\"";        ///< orientation along +z
};

/** The warning for coordinates rounded coarser than half the spacing, if they are. */
std::optional<std::string> quantisationWarning(const PointSpacing& spacing);

/** The warning for a viewpoint too far from the box [min, max] to orient by, when options
 *  orient by a viewpoint (Viewpoint, MeshFaces, or SpanningTree seeded facing it). */
std::optional<std::string> farViewpointWarning(const Eigen::Vector3d& min,
                                               const Eigen::Vector3d& max,
                                               const LocalFitOptions& options,
                                               const OptionSpelling& spelling);

/** The warnings for points without an estimate and points whose quadric fell back to PCA. */
std::vector<std::string> fitResultWarnings(std::int64_t failed_points,
                                           std::int64_t fallback_points);

/** The warnings for a mesh's vertex normals computed with weighting. */
std::vector<std::string> meshNormalWarnings(const MeshNormals& normals, NormalWeighting weighting);

/** The warnings for a mesh's curvatures. */
std::vector<std::string> curvatureWarnings(const VertexCurvatures& curvatures);

}  // namespace pcl_ddg
