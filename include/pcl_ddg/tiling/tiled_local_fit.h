#pragma once
/** \file
 * The fitted estimators (PCA, quadric, robust) run tile by tile, with the same result as on the
 * whole cloud, bit for bit: each tile is processed with a halo that holds every point's whole
 * neighbourhood, and the kd-tree breaks distance ties by point index, so a tile (indexed in the
 * cloud's order) finds exactly the neighbours, in the order, that the whole cloud does.
 *   k nearest  the halo is set so that (nearly) every own point's k-th neighbour lies inside it,
 *              by a margin above float rounding (a first guess from the tile before, widened when
 *              more than 1% of the points look farther); the few points that look farther still
 *              (outliers, the rim of a dense cluster) are fitted with the points around them alone
 *   radius     the halo is the radius (with max_neighbours too: those are cut from the ball)
 *   robust     with k nearest, how far a point looked (its k nearest and the rows its wider planes
 *              read, RobustNormalEstimation::getReaches) is known after its fit: the tile is
 *              fitted and refitted with a wider halo while more than 1% look past it; the rest
 *              are fitted apart, a group of near ones at a time, in boxes that widen until each
 *              looks inside its own
 */
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <functional>

#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/tiling/tile_plan.h"

namespace pcl_ddg {

struct TilingOptions {
  std::int64_t max_points_per_tile = std::int64_t{1} << 20;  ///< own points (the halo adds)
  int resolution = 64;  ///< histogram cells per axis the tiles are cut from
};

struct TilingReport {
  std::size_t tiles = 0;
  std::int64_t halo_growths = 0;    ///< times a tile was gathered again with a wider halo
  std::int64_t far_points = 0;      ///< points fitted apart, with the points around them
  std::int64_t largest_gather = 0;  ///< points fitted at once (own and halo), at most
  double widest_halo = 0.0;         ///< in the cloud's length unit
};

/** Gathered points, by increasing index in the cloud, and which of them to fit: in the whole
 *  cloud's local frame (local_cloud.h), whose origin every tile shares, so that a tile's floats
 *  and doubles are the whole cloud's, bit for bit. */
struct TilePoints {
  pcl::PointCloud<pcl::PointXYZ>::Ptr points;
  /** The points in double (relative to origin), parallel to points; null: the floats. */
  std::shared_ptr<Eigen::Matrix3Xd> positions;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<std::int64_t> global_index;  ///< parallel to points
  pcl::IndicesPtr own;                     ///< positions in points of the points to fit
};

/** Gathers the points inside region and, for tile >= 0, all of that tile's own points (which
 *  are `own`); for tile < 0 `own` is left empty. From memory, or from a tile's files on disk. */
using PointGatherer = std::function<TilePoints(int tile, const Eigen::AlignedBox3d& region)>;

/** Receives fitted points: the gathered points and the fit of their `own` ones, in that order. */
using FitConsumer = std::function<void(const TilePoints&, const LocalFitResult&)>;

/**
 * Fits every tile of the plan (cut from the points' float coordinates in the local frame), one
 * after the other (each fit parallel inside), and hands every finite point's result to consume
 * exactly once. Throws like fitLocalSurfaces;
 * options.neighbourhood must be KdTree (mesh rings need the whole mesh).
 */
void fitTiles(const TilePlan& plan, const LocalFitOptions& options, const PointGatherer& gather,
              const FitConsumer& consume, TilingReport* report = nullptr);

/** fitLocalSurfaces on a cloud in memory, tile by tile: the same result, bit for bit. */
LocalFitResult fitLocalSurfacesTiled(const LocalCloud& cloud, const LocalFitOptions& options,
                                     const TilingOptions& tiling, TilingReport* report = nullptr);

}  // namespace pcl_ddg
