#pragma once
#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "pcl_ddg/search/organized_grid_search.h"
#include "pcl_ddg/search/visit_stamps.h"

namespace pcl_ddg {
namespace detail {

/** Writes the first count (distance, pixel) pairs of found into the outputs. */
inline int writeFound(const std::vector<std::pair<float, pcl::index_t>>& found, std::size_t count,
                      pcl::Indices& k_indices, std::vector<float>& k_sqr_distances) {
  k_indices.resize(count);
  k_sqr_distances.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    k_sqr_distances[i] = found[i].first;
    k_indices[i] = found[i].second;
  }
  return static_cast<int>(count);
}

}  // namespace detail

template <typename PointT>
OrganizedGridSearch<PointT>::OrganizedGridSearch(double max_depth_jump, int max_window_radius)
    : pcl::search::Search<PointT>("OrganizedGridSearch", true),
      max_depth_jump_(max_depth_jump),
      max_window_radius_(max_window_radius) {
  if (!(max_depth_jump_ > 0.0) || !std::isfinite(max_depth_jump_)) {
    throw pcl::BadArgumentException("OrganizedGridSearch: the depth jump must be > 0");
  }
  if (max_window_radius_ < 1) {
    throw pcl::BadArgumentException("OrganizedGridSearch: the window radius must be >= 1");
  }
}

template <typename PointT>
void OrganizedGridSearch<PointT>::setInputCloud(const PointCloudConstPtr& cloud,
                                                const IndicesConstPtr& indices) {
  if (!cloud || cloud->height < 2 || cloud->size() != std::size_t{cloud->width} * cloud->height) {
    throw pcl::BadArgumentException(
        "OrganizedGridSearch needs an organized cloud (width x height pixels, height > 1)");
  }
  if (indices && !indices->empty()) {
    throw pcl::BadArgumentException(
        "OrganizedGridSearch searches the whole image: indices are not supported");
  }
  this->input_ = cloud;
  this->indices_.reset();
  width_ = static_cast<int>(cloud->width);
  height_ = static_cast<int>(cloud->height);
  const Eigen::Vector3f origin = cloud->sensor_origin_.template head<3>();
  range_.resize(cloud->size());
  const std::int64_t size = static_cast<std::int64_t>(cloud->size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < size; ++i) {
    const PointT& p = (*cloud)[i];
    range_[i] = pcl::isXYZFinite(p) ? (p.getVector3fMap() - origin).norm()
                                    : std::numeric_limits<float>::quiet_NaN();
  }
  // Every query walks these steps: their depth tests are made once, here.
  steps_.resize(range_.size());
#pragma omp parallel for schedule(static)
  for (int y = 0; y < height_; ++y) {
    const auto stepsAt = [&](int x) {
      const pcl::index_t from = static_cast<pcl::index_t>(y) * width_ + x;
      std::uint8_t bits = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, v = y + dy;
          if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= width_ || v >= height_) continue;
          if (isJumpFree(from, static_cast<pcl::index_t>(v) * width_ + u))
            bits |= static_cast<std::uint8_t>(1u << stepBit(dx, dy));
        }
      }
      return bits;
    };
    std::uint8_t* steps = &steps_[static_cast<std::size_t>(y) * width_];
    if (y == 0 || y == height_ - 1 || width_ < 3) {
      for (int x = 0; x < width_; ++x) steps[x] = stepsAt(x);
      continue;
    }
    // Inside the image every pixel has 8 neighbours: no bounds to test, the same tests for all.
    steps[0] = stepsAt(0);
    steps[width_ - 1] = stepsAt(width_ - 1);
    const float* above = &range_[static_cast<std::size_t>(y - 1) * width_];
    const float* row = above + width_;
    const float* below = row + width_;
    const auto free = [this](float a, float b) { return rangesJoin(a, b) ? 1u : 0u; };
    for (int x = 1; x < width_ - 1; ++x) {
      const float r = row[x];
      steps[x] = static_cast<std::uint8_t>(
          free(r, above[x - 1]) << stepBit(-1, -1) | free(r, above[x]) << stepBit(0, -1) |
          free(r, above[x + 1]) << stepBit(1, -1) | free(r, row[x - 1]) << stepBit(-1, 0) |
          free(r, row[x + 1]) << stepBit(1, 0) | free(r, below[x - 1]) << stepBit(-1, 1) |
          free(r, below[x]) << stepBit(0, 1) | free(r, below[x + 1]) << stepBit(1, 1));
    }
  }
}

template <typename PointT>
bool OrganizedGridSearch<PointT>::isSearchable(pcl::index_t index) const {
  if (!this->input_) {
    PCL_ERROR("[pcl_ddg::OrganizedGridSearch] no input cloud set\n");
    return false;
  }
  if (index < 0 || index >= static_cast<pcl::index_t>(range_.size())) {
    PCL_ERROR("[pcl_ddg::OrganizedGridSearch] query index %d is not a pixel of the cloud\n",
              static_cast<int>(index));
    return false;
  }
  return std::isfinite(range_[index]);
}

template <typename PointT>
bool OrganizedGridSearch<PointT>::isQueryCloud(const PointCloud& cloud) const {
  if (&cloud == this->input_.get()) return true;
  PCL_ERROR("[pcl_ddg::OrganizedGridSearch] queries must be pixels of the search's own cloud\n");
  return false;
}

template <typename PointT>
float OrganizedGridSearch<PointT>::squaredDistance(pcl::index_t a, pcl::index_t b) const {
  return ((*this->input_)[a].getVector3fMap() - (*this->input_)[b].getVector3fMap()).squaredNorm();
}

template <typename PointT>
bool OrganizedGridSearch<PointT>::isJumpFree(pcl::index_t a, pcl::index_t b) const {
  return rangesJoin(range_[a], range_[b]);
}

template <typename PointT>
template <typename Accept, typename LevelDone>
void OrganizedGridSearch<PointT>::breadthFirst(pcl::index_t start, int max_steps, Accept&& accept,
                                               LevelDone&& level_done) const {
  detail::VisitStamps& visited =
      detail::VisitStamps::forThisThread(static_cast<int>(range_.size()));
  visited.startQuery();
  thread_local std::vector<pcl::index_t> level, next;
  level.assign(1, start);
  visited.visit(start);
  if (!accept(start) || !level_done(0)) return;
  for (int steps = 1; steps <= max_steps && !level.empty(); ++steps) {
    next.clear();
    for (const pcl::index_t from : level) {
      const std::uint8_t steps = steps_[from];
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          if ((du == 0 && dv == 0) || !(steps & (1u << stepBit(du, dv)))) continue;
          const pcl::index_t to = from + static_cast<pcl::index_t>(dv) * width_ + du;
          if (visited.visit(to) && accept(to)) next.push_back(to);
        }
      }
    }
    level.swap(next);
    if (!level_done(steps)) return;
  }
}

template <typename PointT>
template <typename Visit>
int OrganizedGridSearch<PointT>::walkWindow(pcl::index_t index, int window_radius,
                                            Visit&& visit) const {
  // Breadth-first within the window, with marks and a queue local to the window: at most
  // (2w+1)^2 pixels.
  const int u = index % width_, v = index / width_;
  const int x0 = std::max(0, u - window_radius), x1 = std::min(width_ - 1, u + window_radius);
  const int y0 = std::max(0, v - window_radius), y1 = std::min(height_ - 1, v + window_radius);
  const int side = x1 - x0 + 1;
  thread_local std::vector<std::uint8_t> seen;
  thread_local std::vector<pcl::index_t> queue;
  seen.assign(static_cast<std::size_t>(side) * (y1 - y0 + 1), 0);
  seen[static_cast<std::size_t>(v - y0) * side + (u - x0)] = 1;
  queue.assign(1, index);
  for (std::size_t next = 0; next < queue.size(); ++next) {
    const pcl::index_t from = queue[next];
    visit(from);
    const int fu = from % width_, fv = from / width_;
    const std::uint8_t steps = steps_[from];
    for (int y = std::max(y0, fv - 1); y <= std::min(y1, fv + 1); ++y) {
      for (int x = std::max(x0, fu - 1); x <= std::min(x1, fu + 1); ++x) {
        if ((x == fu && y == fv) || !(steps & (1u << stepBit(x - fu, y - fv)))) continue;
        std::uint8_t& mark = seen[static_cast<std::size_t>(y - y0) * side + (x - x0)];
        if (mark) continue;
        mark = 1;
        queue.push_back(static_cast<pcl::index_t>(y) * width_ + x);
      }
    }
  }
  return static_cast<int>(queue.size());
}

template <typename PointT>
int OrganizedGridSearch<PointT>::windowSearch(pcl::index_t index, int window_radius,
                                              pcl::Indices& k_indices,
                                              std::vector<float>& k_sqr_distances) const {
  k_indices.clear();
  k_sqr_distances.clear();
  if (!isSearchable(index) || window_radius < 0) return 0;
  walkWindow(index, window_radius, [&](pcl::index_t pixel) {
    k_indices.push_back(pixel);
    k_sqr_distances.push_back(squaredDistance(index, pixel));
  });
  return static_cast<int>(k_indices.size());
}

template <typename PointT>
int OrganizedGridSearch<PointT>::windowReach(pcl::index_t index, int window_radius) const {
  if (!isSearchable(index) || window_radius < 0) return 0;
  return walkWindow(index, window_radius, [](pcl::index_t) {});
}

template <typename PointT>
int OrganizedGridSearch<PointT>::nearestKSearch(pcl::index_t index, int k, pcl::Indices& k_indices,
                                                std::vector<float>& k_sqr_distances) const {
  k_indices.clear();
  k_sqr_distances.clear();
  if (k < 1 || !isSearchable(index)) return 0;
  thread_local std::vector<std::pair<float, pcl::index_t>> found;
  found.clear();
  int enough_at = -1;
  breadthFirst(
      index, max_window_radius_,
      [&](pcl::index_t pixel) {
        found.emplace_back(squaredDistance(index, pixel), pixel);
        return true;
      },
      [&](int steps) {
        // One level more once k are found: across a slanted surface a pixel one step further
        // can lie nearer.
        if (enough_at < 0 && static_cast<int>(found.size()) >= k) enough_at = steps;
        return enough_at < 0 || steps < enough_at + 1;
      });
  const std::size_t kept = std::min<std::size_t>(found.size(), static_cast<std::size_t>(k));
  std::partial_sort(found.begin(), found.begin() + static_cast<std::ptrdiff_t>(kept), found.end());
  return detail::writeFound(found, kept, k_indices, k_sqr_distances);
}

template <typename PointT>
int OrganizedGridSearch<PointT>::nearestKSearch(const PointCloud& cloud, pcl::index_t index, int k,
                                                pcl::Indices& k_indices,
                                                std::vector<float>& k_sqr_distances) const {
  if (!isQueryCloud(cloud)) {
    k_indices.clear();
    k_sqr_distances.clear();
    return 0;
  }
  return nearestKSearch(index, k, k_indices, k_sqr_distances);
}

template <typename PointT>
int OrganizedGridSearch<PointT>::nearestKSearch(const PointT&, int, pcl::Indices& k_indices,
                                                std::vector<float>& k_sqr_distances) const {
  PCL_ERROR("[pcl_ddg::OrganizedGridSearch] a point query has no pixel: query by pixel index\n");
  k_indices.clear();
  k_sqr_distances.clear();
  return 0;
}

template <typename PointT>
int OrganizedGridSearch<PointT>::radiusSearch(pcl::index_t index, double radius,
                                              pcl::Indices& k_indices,
                                              std::vector<float>& k_sqr_distances,
                                              unsigned int max_nn) const {
  k_indices.clear();
  k_sqr_distances.clear();
  if (!(radius >= 0.0) || !isSearchable(index)) return 0;
  thread_local std::vector<std::pair<float, pcl::index_t>> found;
  found.clear();
  const float squared_radius = static_cast<float>(radius * radius);
  breadthFirst(
      index, max_window_radius_,
      [&](pcl::index_t pixel) {
        const float d = squaredDistance(index, pixel);
        if (d > squared_radius) return false;
        found.emplace_back(d, pixel);
        return true;
      },
      [](int) { return true; });
  std::size_t kept = found.size();
  if (max_nn > 0 && max_nn < kept) {
    kept = max_nn;
    std::partial_sort(found.begin(), found.begin() + static_cast<std::ptrdiff_t>(kept),
                      found.end());
  } else if (this->sorted_results_) {
    std::sort(found.begin(), found.end());
  }
  return detail::writeFound(found, kept, k_indices, k_sqr_distances);
}

template <typename PointT>
int OrganizedGridSearch<PointT>::radiusSearch(const PointCloud& cloud, pcl::index_t index,
                                              double radius, pcl::Indices& k_indices,
                                              std::vector<float>& k_sqr_distances,
                                              unsigned int max_nn) const {
  if (!isQueryCloud(cloud)) {
    k_indices.clear();
    k_sqr_distances.clear();
    return 0;
  }
  return radiusSearch(index, radius, k_indices, k_sqr_distances, max_nn);
}

template <typename PointT>
int OrganizedGridSearch<PointT>::radiusSearch(const PointT&, double, pcl::Indices& k_indices,
                                              std::vector<float>& k_sqr_distances,
                                              unsigned int) const {
  PCL_ERROR("[pcl_ddg::OrganizedGridSearch] a point query has no pixel: query by pixel index\n");
  k_indices.clear();
  k_sqr_distances.clear();
  return 0;
}

}  // namespace pcl_ddg

#define PCL_DDG_INSTANTIATE_OrganizedGridSearch(T) template class pcl_ddg::OrganizedGridSearch<T>;
