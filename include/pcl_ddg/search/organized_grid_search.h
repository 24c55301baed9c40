#pragma once
/** \file
 * Neighbourhoods on an organized cloud's pixel grid (an RGB-D frame, a range image), as a PCL
 * search method: the image-space sibling of MeshRingSearch, usable by any pcl::Feature.
 *
 * The pixels are a graph: two 8-adjacent pixels are joined unless one has no finite point or a
 * depth jump separates them, |r(a) - r(b)| > max_depth_jump * min(r(a), r(b)), with r the range
 * (distance from the cloud's sensor origin). Neighbours are found by breadth-first search over
 * that graph, so they never lie across a jump, however far the other side's points are. The
 * default, 0.02, keeps a surface seen as obliquely as 84 degrees by a 525-pixel focal length (its
 * range grows by tan(angle) / f per pixel, and tan 84.6 deg = 0.02 * 525) and is several times a
 * Kinect-class sensor's depth step (0.3 % of the range at 1 m, 0.9 % at 3 m: Khoshelham and
 * Elberink 2012); a person one metre in front of a wall at 3 m is a 50 % jump.
 *
 *  nearestKSearch(index, k)   the k nearest (Euclidean) of the pixels reached in the fewest
 *                             steps that holds k of them, and of one step more, so that a pixel
 *                             just beyond can still win; the query first. Fewer than k when the
 *                             search reaches maxWindowRadius() steps first.
 *  radiusSearch(index, r)     the pixels reached without leaving the ball of radius r (a
 *                             topological ball on the grid, up to maxWindowRadius() steps);
 *                             sorted by distance if setSortedResults(true); max_nn keeps the
 *                             nearest max_nn.
 *  windowSearch(index, w)     the pixels reached without leaving the (2w+1)^2 window: the
 *                             neighbourhood the window-sum normals (organized_normals.h)
 *                             average over.
 *
 * Distances are squared and in float, as PCL returns them. Queries are pixel indices of the input
 * cloud; a bare point has no pixel and fails with PCL_ERROR. A query at a pixel without a finite
 * point returns nothing. Thread-safe, and a query allocates nothing once its buffers have grown.
 */
#include <pcl/search/search.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace pcl_ddg {

template <typename PointT>
class OrganizedGridSearch : public pcl::search::Search<PointT> {
 public:
  using Ptr = std::shared_ptr<OrganizedGridSearch<PointT>>;
  using ConstPtr = std::shared_ptr<const OrganizedGridSearch<PointT>>;
  using PointCloud = typename pcl::search::Search<PointT>::PointCloud;
  using PointCloudConstPtr = typename pcl::search::Search<PointT>::PointCloudConstPtr;
  using IndicesConstPtr = pcl::IndicesConstPtr;

  static constexpr double kDefaultMaxDepthJump = 0.02;
  static constexpr int kDefaultMaxWindowRadius = 16;

  /** Throws pcl::BadArgumentException unless max_depth_jump > 0 and max_window_radius >= 1. */
  explicit OrganizedGridSearch(double max_depth_jump = kDefaultMaxDepthJump,
                               int max_window_radius = kDefaultMaxWindowRadius);

  double maxDepthJump() const { return max_depth_jump_; }
  int maxWindowRadius() const { return max_window_radius_; }

  /** Throws pcl::BadArgumentException unless cloud is organized (height > 1); restricting the
   *  search to indices is not supported (the grid is the whole image). */
  void setInputCloud(const PointCloudConstPtr& cloud,
                     const IndicesConstPtr& indices = IndicesConstPtr()) override;

  /** Whether the pixels a and b (valid indices) hold finite points with no depth jump between
   *  them; adjacency is not checked. */
  bool isJumpFree(pcl::index_t a, pcl::index_t b) const;

  /** The 8 steps from pixel index that the graph allows, one bit each: bit stepBit(dx, dy) for
   *  the step to (x + dx, y + dy). */
  std::uint8_t allowedSteps(pcl::index_t index) const { return steps_[index]; }
  static constexpr int stepBit(int dx, int dy) {
    return (dy + 1) * 3 + (dx + 1) - ((dy + 1) * 3 + (dx + 1) > 4 ? 1 : 0);
  }

  /** The pixels reached from index within its (2 window_radius + 1)^2 window, query first. */
  int windowSearch(pcl::index_t index, int window_radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances) const;

  /** How many pixels windowSearch would return. */
  int windowReach(pcl::index_t index, int window_radius) const;

  using pcl::search::Search<PointT>::nearestKSearch;
  using pcl::search::Search<PointT>::radiusSearch;

  int nearestKSearch(pcl::index_t index, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;
  int nearestKSearch(const PointCloud& cloud, pcl::index_t index, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;
  /** Not a pixel: fails (PCL_ERROR, 0 results). */
  int nearestKSearch(const PointT& point, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;

  int radiusSearch(pcl::index_t index, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override;
  int radiusSearch(const PointCloud& cloud, pcl::index_t index, double radius,
                   pcl::Indices& k_indices, std::vector<float>& k_sqr_distances,
                   unsigned int max_nn = 0) const override;
  /** Not a pixel: fails (PCL_ERROR, 0 results). */
  int radiusSearch(const PointT& point, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override;

 private:
  /** Whether two adjacent pixels' ranges lie within the depth jump of each other. NaN compares
   *  false: a pixel without a point joins nothing. */
  bool rangesJoin(float a, float b) const {
    return std::abs(a - b) <= max_depth_jump_ * std::min(a, b);
  }
  bool isSearchable(pcl::index_t index) const;
  bool isQueryCloud(const PointCloud& cloud) const;
  float squaredDistance(pcl::index_t a, pcl::index_t b) const;
  /** Breadth-first search from start over jump-free steps, level by level, at most max_steps
   *  levels: accept(pixel) says whether a reached pixel belongs (and is searched on from);
   *  level_done(steps) is called after each level and returns false to stop. */
  /** Breadth-first search within the window; visit(pixel) for each pixel reached. */
  template <typename Visit>
  int walkWindow(pcl::index_t index, int window_radius, Visit&& visit) const;
  template <typename Accept, typename LevelDone>
  void breadthFirst(pcl::index_t start, int max_steps, Accept&& accept,
                    LevelDone&& level_done) const;

  double max_depth_jump_;
  int max_window_radius_;
  int width_ = 0, height_ = 0;
  std::vector<float> range_;         ///< per pixel; NaN where the point is not finite
  std::vector<std::uint8_t> steps_;  ///< per pixel: allowedSteps()
};

}  // namespace pcl_ddg

#ifdef PCL_NO_PRECOMPILE
#include "pcl_ddg/search/impl/organized_grid_search.hpp"
#endif
