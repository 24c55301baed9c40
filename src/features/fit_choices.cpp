#include "pcl_ddg/features/fit_choices.h"

#include <algorithm>
#include <cmath>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/features/robust_normal_estimation.h"

namespace pcl_ddg {

LocalFitMethod chooseFitMethod(const std::string& name, const OptionStyle& style) {
  return chooseNamed<LocalFitMethod>("method", name,
                                     {{"pca", LocalFitMethod::PCA},
                                      {"quadric", LocalFitMethod::Quadric},
                                      {"robust", LocalFitMethod::Robust}},
                                     style);
}

NeighbourhoodKind chooseNeighbourhood(const std::optional<std::string>& name, bool mesh,
                                      bool organized, const OptionStyle& style) {
  const NeighbourhoodKind kind =
      name        ? chooseNamed<NeighbourhoodKind>("neighbours", *name,
                                            {{"rings", NeighbourhoodKind::MeshRings},
                                                    {"kdtree", NeighbourhoodKind::KdTree},
                                                    {"grid", NeighbourhoodKind::Grid},
                                                    {"bfs", NeighbourhoodKind::MeshRings},
                                                    {"knn", NeighbourhoodKind::KdTree}},
                                            style, 3)
      : mesh      ? NeighbourhoodKind::MeshRings
      : organized ? NeighbourhoodKind::Grid
                  : NeighbourhoodKind::KdTree;
  if (kind == NeighbourhoodKind::MeshRings && !mesh) {
    throw pcl::BadArgumentException(style.setting("neighbours", "rings") +
                                    " needs a mesh; this input is a point cloud (use " +
                                    style.name("kdtree") + ")");
  }
  if (kind == NeighbourhoodKind::Grid && !organized) {
    throw pcl::BadArgumentException(style.setting("neighbours", "grid") +
                                    " needs an organized cloud (width x height pixels)");
  }
  return kind;
}

const char* neighbourhoodName(NeighbourhoodKind kind) {
  return kind == NeighbourhoodKind::MeshRings ? "rings"
         : kind == NeighbourhoodKind::Grid    ? "grid"
                                              : "kdtree";
}

NormalOrientation chooseOrientation(const std::string& name, const OptionStyle& style) {
  return chooseNamed<NormalOrientation>("orient", name,
                                        {{"viewpoint", NormalOrientation::Viewpoint},
                                         {"up", NormalOrientation::Up},
                                         {"mst", NormalOrientation::SpanningTree},
                                         {"mesh", NormalOrientation::MeshFaces}},
                                        style);
}

void checkOrientationInput(NormalOrientation orientation, bool mesh, const OptionStyle& style) {
  if (orientation == NormalOrientation::MeshFaces && !mesh) {
    throw pcl::BadArgumentException(style.setting("orient", "mesh") +
                                    " needs a mesh; this input is a point cloud");
  }
}

int defaultNeighbours(LocalFitMethod method, std::int64_t points) {
  switch (method) {
    case LocalFitMethod::Quadric:
      return 20;
    case LocalFitMethod::Robust:
      return static_cast<int>(std::min<std::int64_t>(kRobustNormalNeighbours, points));
    case LocalFitMethod::PCA:
      break;
  }
  return 16;
}

void checkFitRequest(const FitRequest& r, const OptionStyle& style) {
  const auto fail = [](const std::string& message) { throw pcl::BadArgumentException(message); };
  const auto o = [&](const char* name) { return style.option(name); };
  if (r.k && r.radius) {
    fail(o("k") + " and " + o("radius") + " exclude each other (use " +
         style.placeholder("radius", "r") + style.separator + style.placeholder("max_nn", "N") +
         " for both)");
  }
  if (r.max_nn && !r.radius) fail(o("max_nn") + " needs " + o("radius"));
  if (r.k && *r.k < 3) fail(o("k") + " must be at least 3");
  if (r.max_nn && *r.max_nn < 3) fail(o("max_nn") + " must be at least 3");
  if (r.radius && !(*r.radius > 0.0 && std::isfinite(*r.radius)))
    fail(o("radius") + " must be a positive length");
  if (r.min_nn && !r.radius) fail(o("min_nn") + " needs " + o("radius"));
  if (r.min_nn && *r.min_nn < 3) fail(o("min_nn") + " must be at least 3");
  if (r.max_depth_jump && !(*r.max_depth_jump > 0.0))
    fail(o("max_depth_jump") + " must be > 0 (a relative range change per pixel)");
  const NormalOrientation orientation =
      r.orient ? chooseOrientation(*r.orient, style) : NormalOrientation::MeshFaces;
  const bool up_or_tree = r.orient && (orientation == NormalOrientation::Up ||
                                       orientation == NormalOrientation::SpanningTree);
  if (r.up && !up_or_tree) {
    fail(o("up") + " applies to " + style.setting("orient", "up") + " and " +
         style.setting("orient", "mst"));
  }
  if (r.orient && orientation == NormalOrientation::SpanningTree && r.up && r.viewpoint) {
    fail(style.setting("orient", "mst") + " takes one reference: " + o("viewpoint") + " or " +
         o("up"));
  }
}

void applyNeighbourCounts(const FitRequest& request, std::int64_t points, const OptionStyle& style,
                          LocalFitOptions& options) {
  options.k = request.k.value_or(defaultNeighbours(options.method, points));
  if (request.radius) {
    options.radius = *request.radius;
    options.max_neighbours =
        static_cast<unsigned int>(request.max_nn.value_or(kDefaultMaxNeighbours));
    options.min_neighbours = static_cast<unsigned int>(request.min_nn.value_or(0));
  } else if (options.k > points) {
    throw InvalidMeshException(style.option("k") + " " + std::to_string(options.k) +
                               " is more than the " + std::to_string(points) +
                               " points of the input");
  }
}

}  // namespace pcl_ddg
