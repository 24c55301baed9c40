#pragma once
/** \file
 * A kd-tree over 3D points (nanoflann's), queried one point at a time without allocating (the core
 * of KdTreeSearch; nanoflann stays out of the public headers).
 *
 * Why not pcl::KdTreeFLANN: it answers each query through FLANN's batch knnSearch, which opens an
 * OpenMP parallel region per call; inside an estimator that is already parallel over points that
 * costs as much as the search itself; and FLANN searches its own reordered copy of the points
 * (12 bytes a point, 31 with its index while it is built). Here the tree reads the points where
 * they lie (4 bytes a point for its order, about 5 for its nodes) and each query writes straight
 * into the caller's vectors. Reading in place is faster on scans stored in acquisition order and
 * slower on a cloud larger than the cache whose points are in random order (bench_kd_tree: 1.5x
 * faster than pcl::search::KdTree in grid order, 7 % slower shuffled).
 */
#include <pcl/types.h>

#include <memory>
#include <vector>

namespace pcl_ddg {
namespace detail {

class PointKdTree {
 public:
  /** Indexes the points xyz[3 * i .. 3 * i + 2] for i in [0, ids.size()), kept by the tree; their
   *  ids in the answers are ids[i] (the caller's numbering). */
  PointKdTree(std::vector<float> xyz, std::vector<pcl::index_t> ids);
  /** Indexes points where they lie, point i at xyz[stride * i .. stride * i + 2] with id i (a PCL
   *  cloud's floats: not copied, and no ids); they must stay there, unchanged, while the tree is
   *  searched. */
  PointKdTree(const float* xyz, std::size_t stride, std::size_t count);
  ~PointKdTree();
  PointKdTree(const PointKdTree&) = delete;
  PointKdTree& operator=(const PointKdTree&) = delete;

  std::size_t size() const { return size_; }

  /** The k nearest points, sorted by squared distance, ties by id: one answer whatever the tree's
   *  shape (what makes tiled processing equal to whole-cloud processing); returns how many (fewer
   *  if the tree is smaller). */
  int nearestK(const float* query, int k, pcl::Indices& indices,
               std::vector<float>& squared_distances) const;

  /** All points within radius (squared distances below radius^2), sorted by distance if sorted;
   *  max_nn > 0 gives the max_nn nearest within the radius, sorted (a k-nearest query cut at the
   *  radius, so its cost does not grow with the points in the ball). */
  int withinRadius(const float* query, double radius, pcl::Indices& indices,
                   std::vector<float>& squared_distances, unsigned int max_nn, bool sorted) const;

 private:
  struct Index;

  std::vector<float> xyz_;         ///< the points given by value (else the caller's)
  std::vector<pcl::index_t> ids_;  ///< the caller's ids, by the tree's index; empty: the same
  std::size_t size_ = 0;
  std::unique_ptr<Index> index_;
};

}  // namespace detail
}  // namespace pcl_ddg
