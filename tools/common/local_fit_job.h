#pragma once
// The shared shape of the tools that fit local surfaces (pca, quadric): input that is a mesh or a
// point cloud, the neighbourhood options, and normals written under the names the output format
// expects.
#include <pcl/PolygonMesh.h>
#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>

#include "common/tool_common.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/search/point_spacing.h"
#include "pcl_ddg/tiling/out_of_core_fit.h"

namespace pcl_ddg {
namespace tools {

/** A mesh (topology set, coordinates finite) or a point cloud (no topology, NaN points kept). */
struct SurfaceInput {
  pcl::PolygonMesh mesh;  ///< x, y, z as float (PCL's point types); positions holds them exactly
  std::shared_ptr<const MeshTopology> topology;
  Eigen::Matrix3Xd positions;                  ///< double, as read
  pcl::PointCloud<pcl::PointXYZ>::Ptr points;  ///< the same, as PCL points
  /** Mean edge length of a mesh (a cloud's mean nearest-neighbour distance costs a kd-tree, and
   *  is measured by localFitArguments when -radius asks for it). */
  double spacing = 0.0;
  SensorPose sensor_pose;                ///< a PCD's VIEWPOINT (kept for the output)
  std::shared_ptr<const LasLayout> las;  ///< a LAS input's layout (kept for a .las output)
  FieldPrecision coordinate_precision = FieldPrecision::Float;  ///< as the file declares them
};

/** Mean distance from a point to its nearest other point (exact duplicates skipped), over up to
 *  10,000 finite points: a cloud's h. */
double meanSpacing(const pcl::PointCloud<pcl::PointXYZ>::Ptr& points);

/** positions as PCL points (float; NaN kept, is_dense when all are finite). */
pcl::PointCloud<pcl::PointXYZ>::Ptr toXYZ(const Eigen::Matrix3Xd& positions);

/** The normals of a PCL estimator as a 3 x N matrix (NaN kept). */
Eigen::Matrix3Xd normalsOf(const pcl::PointCloud<pcl::Normal>& normals);

/** Loads a mesh or a cloud, with the warnings of loadSurfaceMesh for meshes and a count of
 *  non-finite points for clouds. */
SurfaceInput loadSurfaceInput(const std::string& path, const char* tool_name);

/** "mesh rings, k = 16", "pixel grid, 5 x 5 window", "kd-tree, radius 0.01", ... */
std::string describeNeighbourhood(const LocalFitOptions& options);

/** The syntax of -neighbours, -k, -radius, -max_nn and -viewpoint, checked before any file is
 *  read (UsageError): -k and -radius exclude each other, -max_nn needs -radius. */
void checkLocalFitArguments(const ToolArguments& args);

/** -neighbours bfs|knn (bfs is the default on meshes and impossible on clouds), -k N (at most the
 *  input's point count), and -radius r, where r is a length or a multiple of the input's spacing
 *  written like 2.5h, with at most -max_nn N neighbours (default 64, Open3D's hybrid search) and,
 *  with -min_nn N, the N nearest where the ball holds fewer; -viewpoint x,y,z orients cloud
 *  normals (default: the file's VIEWPOINT); -up x,y,z is the up direction of -orient up and mst. */
LocalFitOptions localFitArguments(const ToolArguments& args, const SurfaceInput& input,
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
 * files have it) become NaN in input.points, so that they are neither fitted nor anyone's
 * neighbour, and every point is still written (NaN there). Prints how many are fitted; returns how
 * many were left out (to subtract from the fit's failures). Throws when the input has no
 * classification or no point of those classes.
 */
std::int64_t keepOnlyClasses(const char* tool_name, const ToolArguments& args, SurfaceInput& input);

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

/** Writes normals as nx ny nz (PLY) or normal_x normal_y normal_z (PCD), and PCL's curvature
 *  (surface variation) as "curvature". */
void setNormalFields(pcl::PCLPointCloud2& cloud, const std::string& output_path,
                     const pcl::PointCloud<pcl::Normal>& normals, FieldPrecision precision);

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
SamplingCheck checkSampling(const char* tool_name, const SurfaceInput& input,
                            const LocalFitOptions& options);

/** After a radius fit that left points without an estimate: the radius that would give 90 % of
 *  the points -min_nn (or 3) neighbours. */
void warnAboutRadius(const char* tool_name, const SamplingCheck& check,
                     const LocalFitOptions& options, const LocalFitResult& result);

/** Warns about points the estimator could not handle or fitted by the fallback. */
void warnAboutLocalFit(const char* tool_name, const LocalFitResult& result);

}  // namespace tools
}  // namespace pcl_ddg
