#include "pcl_ddg/result_warnings.h"

#include <cstdio>

namespace pcl_ddg {
namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

}  // namespace

std::optional<std::string> quantisationWarning(const PointSpacing& spacing) {
  if (!spacing.quantised()) return std::nullopt;
  return "the coordinates are rounded to " + number(spacing.quantum) + " while the points are " +
         number(spacing.median_spacing) +
         " apart (median): neighbourhoods tie and normals snap to the lattice (store the "
         "coordinates in double, or relative to an offset)";
}

std::optional<std::string> farViewpointWarning(const Eigen::Vector3d& min,
                                               const Eigen::Vector3d& max,
                                               const LocalFitOptions& options,
                                               const OptionSpelling& spelling) {
  const bool by_viewpoint =
      options.orientation == NormalOrientation::Viewpoint ||
      options.orientation == NormalOrientation::MeshFaces ||
      (options.orientation == NormalOrientation::SpanningTree && options.seed_facing_viewpoint);
  const Eigen::Vector3d viewpoint = options.viewpoint.value_or(Eigen::Vector3d::Zero());
  const double diagonal = (max - min).norm();
  const double distance = (viewpoint - viewpoint.cwiseMax(min).cwiseMin(max)).norm();  // to box
  if (!by_viewpoint || !(distance > 10.0 * diagonal)) return std::nullopt;
  char where[128];
  std::snprintf(where, sizeof where, "(%.6g, %.6g, %.6g)", viewpoint.x(), viewpoint.y(),
                viewpoint.z());
  return std::string("the viewpoint ") + where + " is " + number(distance / diagonal) +
         " times the data's extent away: normals facing it are oriented almost at random (give "
         "the sensor position with " +
         spelling.viewpoint + ", or use " + spelling.orient_up + " for aerial data)";
}

std::vector<std::string> fitResultWarnings(std::int64_t failed_points,
                                           std::int64_t fallback_points) {
  std::vector<std::string> warnings;
  if (failed_points > 0) {
    warnings.push_back(std::to_string(failed_points) +
                       " points without an estimate (non-finite, or too few neighbours): NaN");
  }
  if (fallback_points > 0) {
    warnings.push_back(std::to_string(fallback_points) +
                       " points with too few neighbours or an ill-conditioned quadric: PCA "
                       "normal, NaN curvatures");
  }
  return warnings;
}

std::vector<std::string> meshNormalWarnings(const MeshNormals& normals, NormalWeighting weighting) {
  std::vector<std::string> warnings;
  if (normals.invalid_vertices > 0) {
    warnings.push_back(std::to_string(normals.invalid_vertices) +
                       " vertices without a normal (NaN), " +
                       std::to_string(normals.cancelled_vertices) +
                       " of them because their face normals cancel (reversed duplicate faces?)");
  }
  if (weighting == NormalWeighting::MeanCurvature && normals.fallback_vertices > 0) {
    warnings.push_back(std::to_string(normals.fallback_vertices) +
                       " flat or boundary vertices took the area-weighted normal");
  }
  return warnings;
}

std::vector<std::string> curvatureWarnings(const VertexCurvatures& c) {
  std::vector<std::string> warnings;
  if (c.invalid_vertices > c.unoriented_vertices) {
    warnings.push_back(std::to_string(c.invalid_vertices - c.unoriented_vertices) +
                       " vertices without area (NaN)");
  }
  if (c.unoriented_vertices > 0) {
    warnings.push_back(std::to_string(c.unoriented_vertices) +
                       " vertices whose face normals cancel (reversed duplicate faces?): H, k1, "
                       "k2 NaN there");
  }
  return warnings;
}

}  // namespace pcl_ddg
