#include "pcl_ddg/search/point_kd_tree.h"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>

namespace pcl_ddg {
namespace detail {
namespace {

// Points per leaf: as fast as 10 at k = 16 on a 10M-point terrain with half the nodes (32: 4 %
// slower).
constexpr int kLeafSize = 20;

// The smallest float above d >= 0: its bits plus one (infinity stays), without a libm call in the
// search's innermost loop.
float nextFloatUp(float d) {
  if (!(d > 0.0f)) return std::numeric_limits<float>::denorm_min();
  if (d == std::numeric_limits<float>::infinity()) return d;
  std::uint32_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  ++bits;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

// The caller's id of the tree's point index.
struct CallerIds {
  const pcl::index_t* ids;  ///< null: the same
  pcl::index_t operator()(std::size_t index) const {
    return ids ? ids[index] : static_cast<pcl::index_t>(index);
  }
};

// Keeps the k nearest in the caller's vectors, ordered by (distance, index): ties are broken by
// the point's index, so the answer is one set in one order whatever the tree's shape or the order
// the points were visited in (a tile of a cloud, indexed in the cloud's order, gets the same
// neighbours as the whole cloud; see pcl_ddg/tiling). Indices are the caller's from the start.
class NearestK {
 public:
  NearestK(std::size_t k, CallerIds ids, pcl::Indices& indices, std::vector<float>& distances)
      : k_(k), ids_(ids), indices_(indices), distances_(distances) {
    indices_.resize(k);
    distances_.resize(k);
  }
  bool full() const { return count_ == k_; }
  // nanoflann admits a point only strictly below this: one ulp above the k-th distance lets the
  // ties through, to be decided by index.
  float worstDist() const { return worst_; }
  bool addPoint(float distance, std::uint32_t index) {
    const pcl::index_t id = ids_(index);
    if (count_ == k_ && !precedes(distance, id, k_ - 1)) return true;
    std::size_t i = count_ < k_ ? count_++ : k_ - 1;
    for (; i > 0 && precedes(distance, id, i - 1); --i) {
      distances_[i] = distances_[i - 1];
      indices_[i] = indices_[i - 1];
    }
    distances_[i] = distance;
    indices_[i] = id;
    if (count_ == k_) worst_ = nextFloatUp(distances_[k_ - 1]);
    return true;  // search on
  }
  std::size_t count() const { return count_; }

 private:
  bool precedes(float distance, pcl::index_t id, std::size_t slot) const {
    return distance < distances_[slot] || (distance == distances_[slot] && id < indices_[slot]);
  }

  std::size_t k_, count_ = 0;
  CallerIds ids_;
  float worst_ = std::numeric_limits<float>::max();
  pcl::Indices& indices_;
  std::vector<float>& distances_;
};

// Everything within the radius, appended to the caller's vectors.
class WithinRadius {
 public:
  WithinRadius(float squared_radius, pcl::Indices& indices, std::vector<float>& distances)
      : squared_radius_(squared_radius), indices_(indices), distances_(distances) {
    indices_.clear();
    distances_.clear();
  }
  bool full() const { return true; }
  float worstDist() const { return squared_radius_; }
  bool addPoint(float distance, std::uint32_t index) {
    distances_.push_back(distance);  // below the radius: nanoflann admits only those
    indices_.push_back(static_cast<pcl::index_t>(index));
    return true;
  }

 private:
  float squared_radius_;
  pcl::Indices& indices_;
  std::vector<float>& distances_;
};

}  // namespace

// Point i at xyz[stride * i .. stride * i + 2], read where it lies (nanoflann's dataset adaptor).
struct StridedPoints {
  const float* xyz;
  std::size_t stride, count;
  std::size_t kdtree_get_point_count() const { return count; }
  float kdtree_get_pt(std::size_t i, std::size_t d) const { return xyz[stride * i + d]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;  // nanoflann measures it
  }
};

// nanoflann's single kd-tree over the points where they lie: 4 bytes a point for its order and
// about 5 for its nodes (FLANN's, which searched its own reordered copy, held 23, and 31 while it
// was built). Its squared distances are those of pcl::search::KdTree (FLANN's) to the bit, the
// same float sums in the same order, and so are the neighbours, ties broken by index above.
struct PointKdTree::Index {
  using Tree =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, StridedPoints>,
                                          StridedPoints, 3, std::uint32_t>;
  Index(const float* xyz, std::size_t stride, std::size_t count)
      : points{xyz, stride, count},
        tree(3, points, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize)) {}
  template <class Result>
  void search(Result& result, const float* query) const {
    tree.findNeighbors(result, query, nanoflann::SearchParams());
  }
  StridedPoints points;  // before tree, which keeps a reference to it
  Tree tree;
};

PointKdTree::PointKdTree(std::vector<float> xyz, std::vector<pcl::index_t> ids)
    : xyz_(std::move(xyz)), ids_(std::move(ids)), size_(ids_.size()) {
  if (size_ > 0) index_ = std::make_unique<Index>(xyz_.data(), 3, size_);
}

PointKdTree::PointKdTree(const float* xyz, std::size_t stride, std::size_t count) : size_(count) {
  if (size_ > 0) index_ = std::make_unique<Index>(xyz, stride, size_);
}

PointKdTree::~PointKdTree() = default;

int PointKdTree::nearestK(const float* query, int k, pcl::Indices& indices,
                          std::vector<float>& squared_distances) const {
  if (!index_ || k <= 0) {
    indices.clear();
    squared_distances.clear();
    return 0;
  }
  NearestK result(std::min<std::size_t>(k, size_), CallerIds{ids_.empty() ? nullptr : ids_.data()},
                  indices, squared_distances);
  index_->search(result, query);
  indices.resize(result.count());
  squared_distances.resize(result.count());
  return static_cast<int>(indices.size());
}

int PointKdTree::withinRadius(const float* query, double radius, pcl::Indices& indices,
                              std::vector<float>& squared_distances, unsigned int max_nn,
                              bool sorted) const {
  indices.clear();
  squared_distances.clear();
  if (!index_ || !(radius >= 0.0)) return 0;
  const float squared_radius = static_cast<float>(radius * radius);
  if (max_nn > 0) {
    // Hybrid search (Open3D's): the max_nn nearest, cut at the radius. Its cost is that of a
    // k-nearest query, however many points the ball holds (dense or duplicated scans).
    nearestK(query, static_cast<int>(max_nn), indices, squared_distances);
    std::size_t keep = 0;
    for (std::size_t i = 0; i < indices.size(); ++i) {
      if (squared_distances[i] > squared_radius) continue;
      indices[keep] = indices[i];
      squared_distances[keep++] = squared_distances[i];
    }
    indices.resize(keep);
    squared_distances.resize(keep);
    return static_cast<int>(keep);
  }
  const CallerIds id{ids_.empty() ? nullptr : ids_.data()};
  WithinRadius result(squared_radius, indices, squared_distances);
  index_->search(result, query);
  if (sorted) {
    // Sort (distance, index) pairs through a permutation.
    std::vector<std::size_t> order(indices.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return squared_distances[a] < squared_distances[b] ||
             (squared_distances[a] == squared_distances[b] && id(indices[a]) < id(indices[b]));
    });
    pcl::Indices sorted_indices(order.size());
    std::vector<float> sorted_distances(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      sorted_indices[i] = indices[order[i]];
      sorted_distances[i] = squared_distances[order[i]];
    }
    indices.swap(sorted_indices);
    squared_distances.swap(sorted_distances);
  }
  for (pcl::index_t& i : indices) i = id(i);
  return static_cast<int>(indices.size());
}

}  // namespace detail
}  // namespace pcl_ddg
