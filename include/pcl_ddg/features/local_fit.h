#pragma once
/** \file
 * One call for the fitted estimators on a plain xyz cloud, with either kind of neighbourhood:
 * what the tools and the neighbourhood comparison use. (The estimators themselves take any PCL
 * search method; this only chooses between the two this library is about.)
 */
#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/search.h>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "pcl_ddg/features/consistent_orientation.h"
#include "pcl_ddg/features/normal_orientation.h"
#include "pcl_ddg/mesh/local_cloud.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

enum class LocalFitMethod { PCA, Quadric, Robust };

enum class NeighbourhoodKind {
  MeshRings,  ///< MeshRingSearch over the mesh's edges (needs a topology)
  KdTree,     ///< Euclidean: KdTreeSearch (nanoflann)
  Grid        ///< an organized cloud's pixel grid: OrganizedGridSearch
};

struct LocalFitOptions {
  LocalFitMethod method = LocalFitMethod::PCA;
  NeighbourhoodKind neighbourhood = NeighbourhoodKind::KdTree;
  int k = 16;                       ///< neighbours, when radius is 0
  double radius = 0.0;              ///< > 0: a radius search instead of k nearest
  unsigned int max_neighbours = 0;  ///< with radius: keep at most this many, the nearest (0: all)
  /** With radius: fewer in the ball than this, the nearest this many instead (0: the ball). */
  unsigned int min_neighbours = 0;
  unsigned int threads = 0;  ///< 0: all cores
  /** Grid: the relative range change per pixel that cuts the grid (OrganizedGridSearch). */
  double max_depth_jump = 0.02;
  /** Clouds: normals are turned towards this point (a PCD's VIEWPOINT); unset: the origin, as
   *  PCL does. Meshes are oriented like their faces. */
  std::optional<Eigen::Vector3d> viewpoint;
  /** normal_orientation.h. MeshFaces (the default) orients a mesh like its faces and a cloud
   *  towards the viewpoint. SpanningTree propagates over the mesh's edges, the pixel grid, or
   *  the 10 nearest points, as consistent_orientation.h. */
  NormalOrientation orientation = NormalOrientation::MeshFaces;
  /** SpanningTree: the viewpoint decides the signs it can (consistent_orientation.h); false: up
   *  does if set, else each tree's highest point faces +z. */
  bool seed_facing_viewpoint = false;
  /** Up: n . up >= 0 (unset: +z); SpanningTree without seed_facing_viewpoint: the reference. */
  std::optional<Eigen::Vector3d> up;
  /** KdTree: this search method instead of a new KdTreeSearch (one that also records what it
   *  finds, say). */
  std::shared_ptr<pcl::search::Search<pcl::PointXYZ>> kd_tree_search;
  /** Robust, on a tile of a cloud (tiled_local_fit.h): the whole cloud's finite points
   *  (RobustNormalEstimation::setCloudPoints; 0: the tile's), and whether to report each
   *  point's reach (LocalFitResult::reaches). */
  std::int64_t cloud_points = 0;
  bool report_reaches = false;
};

struct LocalFitResult {
  pcl::PointCloud<pcl::Normal> normals;  ///< NaN where failed (see PCANormalEstimation)
  /** Quadric only: principal curvatures and directions (see QuadricNormalEstimation). */
  pcl::PointCloud<pcl::PrincipalCurvatures> curvatures;
  std::int64_t failed_points = 0;
  std::int64_t fallback_points = 0;  ///< quadric: PCA normal used
  /** Robust only: per point the neighbours used and the confidence (RobustNormalEstimation). */
  std::vector<float> scales, confidences;
  /** Robust with options.report_reaches: RobustNormalEstimation::getReaches. */
  std::vector<double> reaches;
  ConsistentOrientationReport orientation;  ///< SpanningTree: what the propagation turned
};

/**
 * Runs PCANormalEstimation, QuadricNormalEstimation or RobustNormalEstimation on cloud: searched
 * in its float points, fitted in its double positions when it has them (local_cloud.h), all in
 * its local frame (options.viewpoint is in world coordinates; normals and curvatures do not
 * depend on the frame). PCA on the grid of a whole organized cloud takes the window-sum path
 * (computeOrganizedPCANormals) over the smallest square window of at least k pixels, and keeps
 * the cloud's width x height. With a topology (one vertex per point) normals are oriented like
 * its faces, whichever neighbourhood is used, so that the two neighbourhoods can be compared point
 * by point; without one, towards the viewpoint (the origin by default) as PCL does; or along a
 * spanning tree (options.orientation). Throws pcl::BadArgumentException for MeshRings without a
 * topology or a bad k / radius.
 */
LocalFitResult fitLocalSurfaces(const LocalCloud& cloud,
                                const std::shared_ptr<const MeshTopology>& topology,
                                const LocalFitOptions& options);

/** The half-width of the smallest square pixel window of at least k pixels (at least 1). */
int gridWindowRadius(int k);

/** The same for the points `indices` only (one output per index, in their order), their
 *  neighbours taken from the whole cloud: how a tile with a halo is processed. */
LocalFitResult fitLocalSurfaces(const LocalCloud& cloud,
                                const std::shared_ptr<const MeshTopology>& topology,
                                const LocalFitOptions& options, const pcl::IndicesPtr& indices);

/** Receives the fits of points first .. first + slice.normals.size() - 1 (to move from). */
using LocalFitSlice = std::function<void(std::size_t first, LocalFitResult& slice)>;

/**
 * fitLocalSurfaces a slice of at most slice_points points at a time (their neighbours from the
 * whole cloud), each slice's result handed to take and then freed: every point's fit the same, to
 * the last bit (a point's fit depends on its neighbourhood only, and every slice searches the same
 * kd-tree), while the output (32 bytes a point as pcl::Normal) and the order the fits visit are
 * held for one slice, not for the whole cloud. One slice for all where the fits need each other
 * or another search than the kd-tree: orientation along a spanning tree, robust normals (whose
 * wider planes are summed over the whole cloud at every compute), a mesh (whose faces' normals
 * orient the fits, made for the whole mesh at every compute), mesh rings, the grid.
 * Returns the counts (failed, fell back) summed over the slices, without normals.
 */
LocalFitResult fitLocalSurfacesInSlices(const LocalCloud& cloud,
                                        const std::shared_ptr<const MeshTopology>& topology,
                                        const LocalFitOptions& options, std::size_t slice_points,
                                        const LocalFitSlice& take);

}  // namespace pcl_ddg
