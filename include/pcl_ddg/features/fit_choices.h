#pragma once
/** \file
 * The local fits' options as the front ends take them (pcl_ddg_normals, pcl_ddg_curvature, the
 * viewer, the Python module, the Dask runner): the names of methods, neighbourhoods and
 * orientations, the default k, and the checks of k, radius, max_nn, min_nn and max_depth_jump,
 * each with one message naming the options in the caller's style (option_style.h). Errors are
 * pcl::BadArgumentException, but for a k above the points (InvalidMeshException: the data, not
 * the option, is at fault).
 */
#include <cstdint>
#include <optional>
#include <string>

#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/option_style.h"

namespace pcl_ddg {

/** pca | quadric | robust. */
LocalFitMethod chooseFitMethod(const std::string& name, const OptionStyle& style);

/**
 * rings | kdtree | grid (bfs and knn: the former spellings of rings and kdtree); none: rings on a
 * mesh, grid on an organized cloud, else kdtree. Throws for rings without a mesh, grid without an
 * organized cloud.
 */
NeighbourhoodKind chooseNeighbourhood(const std::optional<std::string>& name, bool mesh,
                                      bool organized, const OptionStyle& style);

/** The name chooseNeighbourhood reads for kind (rings, kdtree, grid). */
const char* neighbourhoodName(NeighbourhoodKind kind);

/** viewpoint | up | mst | mesh. */
NormalOrientation chooseOrientation(const std::string& name, const OptionStyle& style);

/** Throws for orient mesh on an input without a mesh. */
void checkOrientationInput(NormalOrientation orientation, bool mesh, const OptionStyle& style);

/** The k of a method when none is given: PCA 16, quadric 20, robust kRobustNormalNeighbours or
 *  all the points when fewer. */
int defaultNeighbours(LocalFitMethod method, std::int64_t points);

constexpr unsigned int kDefaultMaxNeighbours = 64;  ///< a radius search's cap when none is given

/** The counts and lengths a fit is asked for; unset: not given. */
struct FitRequest {
  std::optional<int> k, max_nn, min_nn;
  std::optional<double> radius;          ///< a length (the tools' "2.5h" already resolved)
  std::optional<double> max_depth_jump;  ///< grid neighbourhoods only
  std::optional<std::string> orient;     ///< a name chooseOrientation reads
  bool viewpoint = false, up = false;    ///< given
};

/**
 * What needs no data: k excludes radius, max_nn and min_nn need radius, k, max_nn and min_nn at
 * least 3, radius a positive finite length, max_depth_jump > 0; up only with orient up or mst;
 * mst takes one reference, viewpoint or up.
 */
void checkFitRequest(const FitRequest& request, const OptionStyle& style);

/**
 * options' neighbour counts from a checked request: k (or the method's default) for points
 * points, or radius with max_nn (default 64) and min_nn (default 0). Throws
 * InvalidMeshException for a k above points (without a radius).
 */
void applyNeighbourCounts(const FitRequest& request, std::int64_t points, const OptionStyle& style,
                          LocalFitOptions& options);

}  // namespace pcl_ddg
