#pragma once
// The steps the fitting tools (pca, quadric, robust) share: the neighbourhood options, the checks
// of the sampling before a fit, the out-of-core run (-memory) and the warnings after a fit.
#include <pcl/PolygonMesh.h>
#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>

#include "common/tool_common.h"
#include "common/tool_input.h"
#include "pcl_ddg/features/fit_choices.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/search/point_spacing.h"
#include "pcl_ddg/tiling/out_of_core_fit.h"

namespace pcl_ddg {
namespace tools {

/** -neighbours rings|kdtree|grid (bfs and knn: the former spellings), the name checked; none
 *  when not given. */
std::optional<NeighbourhoodKind> requestedNeighbourhood(const ToolArguments& args);

/** -orient viewpoint|up|mst|mesh, the name checked; none when not given. */
std::optional<NormalOrientation> orientationArgument(const ToolArguments& args);

/** "mesh rings, k = 16", "pixel grid, 5 x 5 window", "kd-tree, radius 0.01", ... */
std::string describeNeighbourhood(const LocalFitOptions& options);

/** -neighbours, -k, -radius, -max_nn, -min_nn, -max_depth_jump, -viewpoint, -up, -orient and
 *  -classes, checked before any file is read (UsageError): the library's checkFitRequest
 *  (fit_choices.h) and the tools' own syntax (x,y,z, 2.5h, 2,6). */
void checkLocalFitArguments(const ToolArguments& args);

/** -neighbours rings|kdtree|grid (rings is the default on meshes and impossible on clouds, grid
 *  the default on organized clouds), -k N (at most the
 *  input's point count), and -radius r, where r is a length or a multiple of the input's spacing
 *  written like 2.5h, with at most -max_nn N neighbours (default 64, Open3D's hybrid search) and,
 *  with -min_nn N, the N nearest where the ball holds fewer; -viewpoint x,y,z orients cloud
 *  normals (default: the file's VIEWPOINT); -up x,y,z is the up direction of -orient up and mst. */
LocalFitOptions localFitArguments(const ToolArguments& args, ToolInput& input,
                                  LocalFitMethod method);

/** The options of localFitArguments for a cloud file fitted out of core (-memory): kd-tree
 *  neighbourhoods, -k, or -radius as a length (a multiple of the spacing needs the whole cloud),
 *  -max_nn, -viewpoint (unset: the file's VIEWPOINT). */
LocalFitOptions outOfCoreFitArguments(const ToolArguments& args, LocalFitMethod method);

/** -classes 2,6: the classification values (0-255) to fit, checked before any file is read
 *  (UsageError); empty without -classes. */
std::vector<int> classesArgument(const ToolArguments& args);

/**
 * With -classes: the points of other classes (by the input's `classification` field, as LAS
 * files have it) become NaN in input.local() (floats and doubles), so that they are neither fitted
 * nor anyone's neighbour, and every point is still written (NaN there). Prints how many are fitted;
 * returns how many were left out (to subtract from the fit's failures). Throws when the input has
 * no classification or no point of those classes.
 */
std::int64_t keepOnlyClasses(const char* tool_name, const ToolArguments& args, ToolInput& input);

/** Aerial LiDAR has no single viewpoint: a LAS input fitted without -viewpoint or -orient is
 *  oriented up (as PDAL's filters.normal), which this says in one line; other inputs keep
 *  options as they are. */
void orientLasUp(const char* tool_name, const ToolArguments& args, bool las_input,
                 LocalFitOptions& options);

/** -memory SIZE (like 2G, 512M), checked before any file is read (UsageError). */
std::uint64_t memoryArgument(const ToolArguments& args);

/** Adds a tool's fields for a fit to a piece of its output (the piece of the input the fit is of).
 */
using PieceFields = std::function<void(pcl::PCLPointCloud2& piece, const std::string& output,
                                       const LocalFitResult& fit)>;

/**
 * The -memory path of the fitting tools, on every input (forEachInput): fitCloudFileOutOfCore
 * with a timing line, the tiling's figures and the warnings of warnAboutLocalFit. Each piece gets
 * what the in-memory path writes: float x y z first (double when the file declares double or
 * `precision` asks), and the fields `add` sets.
 */
int fitEachInputOutOfCore(const char* tool_name, const ToolArguments& args,
                          const LocalFitOptions& options, FieldPrecision precision,
                          const PieceFields& add);

/** While alive, PCL prints errors only: the estimators' own warnings would repeat, in the middle
 *  of a timing line, the counts that warnAboutLocalFit reports after it. */
class QuietPCLWarnings {
 public:
  QuietPCLWarnings();
  ~QuietPCLWarnings();
  QuietPCLWarnings(const QuietPCLWarnings&) = delete;
  QuietPCLWarnings& operator=(const QuietPCLWarnings&) = delete;

 private:
  int level_;
};

/** Warns when the cloud's coordinate quantum exceeds half its median spacing (point_spacing.h,
 *  as PCL's float points see them); returns both. */
PointSpacing warnAboutQuantisation(const char* tool_name,
                                   const pcl::PointCloud<pcl::PointXYZ>& points);

/** What checkSampling measured that a warning after the fit needs. */
struct SamplingCheck {
  std::optional<RadiusNeighbourCounts> radius_counts;  ///< with -radius
};

/**
 * Before a fit on a cloud (point_spacing.h): warns when its coordinates are quantised coarser
 * than half its spacing, and when the viewpoint that orients the normals is farther from the
 * data than 10 times its bounding box's diagonal; with -radius, prints how many points the ball
 * holds (min, median, share under 3). Meshes: nothing.
 */
SamplingCheck checkSampling(const char* tool_name, ToolInput& input,
                            const LocalFitOptions& options);

/** After a radius fit that left points without an estimate: the radius that would give 90 % of
 *  the points -min_nn (or 3) neighbours. */
void warnAboutRadius(const char* tool_name, const SamplingCheck& check,
                     const LocalFitOptions& options, const LocalFitResult& result);

/** Warns about points the estimator could not handle or fitted by the fallback. */
void warnAboutLocalFit(const char* tool_name, const LocalFitResult& result);

}  // namespace tools
}  // namespace pcl_ddg
