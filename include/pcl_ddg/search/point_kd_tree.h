#pragma once
/** \file
 * A FLANN kd-tree over 3D points, queried one point at a time without allocating (the core of
 * KdTreeSearch; FLANN itself stays out of the public headers).
 *
 * Why not pcl::KdTreeFLANN: it answers each query through FLANN's batch knnSearch, which opens an
 * OpenMP parallel region per call; inside an estimator that is already parallel over points that
 * costs as much as the search itself. Here each query calls the index's findNeighbors directly
 * with a result set that writes straight into the caller's vectors.
 */
#include <pcl/types.h>

#include <memory>
#include <vector>

namespace pcl_ddg {
namespace detail {

class PointKdTree {
 public:
  /** Indexes the points xyz[3 * i .. 3 * i + 2] for i in [0, count); their ids in the answers are
   *  ids[i] (the caller's numbering). */
  PointKdTree(std::vector<float> xyz, std::vector<pcl::index_t> ids);
  /** Indexes points where they lie, point i at xyz[stride * i .. stride * i + 2] with id i (a PCL
   *  cloud's floats: not first copied, and no ids), read while the tree is built. */
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
  void build(const float* xyz, std::size_t stride);

  std::vector<pcl::index_t> ids_;  ///< the caller's ids, by FLANN's index; empty: the same
  std::size_t size_ = 0;
  std::unique_ptr<Index> index_;
};

}  // namespace detail
}  // namespace pcl_ddg
