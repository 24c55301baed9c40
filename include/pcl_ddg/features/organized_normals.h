#pragma once
/** \file
 * PCA normals of an organized cloud (an RGB-D frame, a range image) at frame rate: each pixel's
 * plane is fitted to the finite points of the (2w+1)^2 pixel window around it, from windowed sums
 * of x, y, z and their products, so that no pixel needs a search. A tile's rows are summed across
 * the window once and then down it (direct sums, no summed-area tables), and a row's eigenpairs are
 * found together in the CPU's vector lanes (fitPlaneNormals).
 *
 * Far from the origin the sums of squares would cancel the covariance away: the sums are formed
 * per 64 x 64 tile on coordinates relative to the tile's mean, so that a window's covariance is
 * as exact as the two-pass PCA of its points (1e-9 relative or better).
 *
 * Across a depth jump a window would mix two surfaces. Where the window holds a point that
 * OrganizedGridSearch::windowSearch does not reach from its centre (a jump, or a hole, lies
 * between them), that pixel's plane is fitted to the points it reaches instead: the same PCA on
 * fewer points, never across the jump. Pixels without a finite point keep NaN; holes are never
 * filled.
 */
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>

#include "pcl_ddg/search/organized_grid_search.h"

namespace pcl_ddg {

struct OrganizedNormalOptions {
  int window_radius = 3;  ///< w: the window is (2w+1)^2 pixels
  double max_depth_jump = OrganizedGridSearch<pcl::PointXYZ>::kDefaultMaxDepthJump;
  unsigned int threads = 0;  ///< 0: all cores
  /** Normals are turned towards this point; unset: the cloud's sensor origin. */
  std::optional<Eigen::Vector3d> viewpoint;
  /** The cloud's coordinates in double (column i: pixel i), summed and fitted instead of its
   *  floats, which still decide which pixels are finite and where the grid is cut (local_cloud.h);
   *  null: the floats. */
  std::shared_ptr<const Eigen::Matrix3Xd> positions;
};

struct OrganizedNormalResult {
  /** width x height of the input; normal and PCL's curvature (surface variation), NaN where the
   *  pixel has no finite point or no plane. */
  pcl::PointCloud<pcl::Normal> normals;
  std::int64_t failed_points = 0;  ///< finite points without a plane (< 3 neighbours, a line)
  std::int64_t window_points = 0;  ///< fitted from the window sums (the whole window)
  std::int64_t jump_points = 0;    ///< a jump (or hole) cuts the window: fitted point by point
  /** The pixel grid the windows were cut by, for further work on the same cloud (e.g. orienting
   *  the normals along it) without building it again. */
  std::shared_ptr<const OrganizedGridSearch<pcl::PointXYZ>> grid;
};

/** Throws pcl::BadArgumentException unless cloud is organized, window_radius >= 1,
 *  max_depth_jump > 0 and positions (if given) has a column per pixel. */
OrganizedNormalResult computeOrganizedPCANormals(
    const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
    const OrganizedNormalOptions& options = OrganizedNormalOptions());

}  // namespace pcl_ddg
