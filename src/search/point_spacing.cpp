#include "pcl_ddg/search/point_spacing.h"

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <boost/sort/spreadsort/integer_sort.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "pcl_ddg/search/point_kd_tree.h"

namespace pcl_ddg {
namespace {

std::vector<pcl::index_t> finitePoints(const pcl::PointCloud<pcl::PointXYZ>& cloud) {
  std::vector<pcl::index_t> finite;
  finite.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (pcl::isXYZFinite(cloud[i])) finite.push_back(static_cast<pcl::index_t>(i));
  return finite;
}

detail::PointKdTree treeOf(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                           std::vector<pcl::index_t> finite) {
  std::vector<float> xyz;
  xyz.reserve(3 * finite.size());
  for (const pcl::index_t i : finite) xyz.insert(xyz.end(), {cloud[i].x, cloud[i].y, cloud[i].z});
  return detail::PointKdTree(std::move(xyz), std::move(finite));
}

/** The stride that takes about `samples` of n points (at least 1). */
std::size_t sampleStride(std::size_t n, int samples) {
  return std::max<std::size_t>(1, n / std::max(1, samples));
}

/** Every stride-th of the finite points, about `samples` of them. */
std::vector<pcl::index_t> sample(const std::vector<pcl::index_t>& finite, int samples) {
  const std::size_t stride = sampleStride(finite.size(), samples);
  std::vector<pcl::index_t> chosen;
  for (std::size_t i = 0; i < finite.size(); i += stride) chosen.push_back(finite[i]);
  return chosen;
}

// A finite float's bits as an unsigned key of the same order: negatives (sign bit set) reversed
// below the positives. -0 and +0 get neighbouring keys (their gap, 0, is no quantum).
std::uint32_t orderedKey(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, 4);
  return bits & 0x80000000u ? ~bits : bits | 0x80000000u;
}

float valueOf(std::uint32_t key) {
  const std::uint32_t bits = key & 0x80000000u ? key & 0x7fffffffu : ~key;
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}

template <typename T>
T median(std::vector<T> values) {
  if (values.empty()) return T(0);
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

}  // namespace

void CoordinateValues::reserve(std::size_t points) {
  for (auto& keys : keys_) keys.reserve(points);
}

void CoordinateValues::add(const float* xyz) {
  if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) return;
  for (int d = 0; d < 3; ++d) keys_[d].push_back(orderedKey(xyz[d]));
}

CoordinateSpread CoordinateValues::spread() {
  // Each axis's values sorted by radix, the three axes side by side (Boost's integer_sort: 0.17 s
  // for 10M values, std::sort 0.68 s; its float_sort computes differences of signed ints that
  // overflow).
  std::array<double, 3> smallest{}, extent{};
#pragma omp parallel for schedule(static, 1) if (size() > 100000)
  for (int d = 0; d < 3; ++d) {
    std::vector<std::uint32_t>& keys = keys_[d];
    if (keys.empty()) continue;
    boost::sort::spreadsort::integer_sort(keys.begin(), keys.end());
    for (std::size_t i = 1; i < keys.size(); ++i) {
      const double gap = static_cast<double>(valueOf(keys[i])) - valueOf(keys[i - 1]);
      if (gap > 0.0 && (smallest[d] == 0.0 || gap < smallest[d])) smallest[d] = gap;
    }
    extent[d] = static_cast<double>(valueOf(keys.back())) - valueOf(keys.front());
  }
  CoordinateSpread spread;
  double diagonal_squared = 0.0;
  for (int d = 0; d < 3; ++d) {
    spread.quantum = std::max(spread.quantum, smallest[d]);
    diagonal_squared += extent[d] * extent[d];
  }
  spread.diagonal = std::sqrt(diagonal_squared);
  return spread;
}

namespace {

/** medianSpacing of the n points x, y, z at xyz + stride * i, read where they lie. */
double medianSpacing(const float* xyz, std::size_t stride, std::size_t n, int samples) {
  if (n < 2) return 0.0;
  const detail::PointKdTree tree(xyz, stride, n);
  const std::size_t step = sampleStride(n, samples);
  std::vector<double> nearest;
  pcl::Indices found;
  std::vector<float> distances;
  for (std::size_t i = 0; i < n; i += step) {
    // Exact duplicates are skipped: the spacing is between distinct samples.
    tree.nearestK(xyz + stride * i, 16, found, distances);
    for (const float d : distances) {
      if (d > 0.0f) {
        nearest.push_back(std::sqrt(static_cast<double>(d)));
        break;
      }
    }
  }
  return median(std::move(nearest));
}

}  // namespace

double medianSpacing(const std::vector<float>& xyz, int samples) {
  return medianSpacing(xyz.data(), 3, xyz.size() / 3, samples);
}

PointSpacing measurePointSpacing(const pcl::PointCloud<pcl::PointXYZ>& cloud, int samples) {
  PointSpacing result;
  const std::vector<pcl::index_t> finite = finitePoints(cloud);
  if (finite.size() < 2) return result;
  CoordinateValues values;
  values.reserve(finite.size());
  for (const pcl::index_t i : finite) values.add(cloud[i].data);
  const CoordinateSpread spread = values.spread();
  result.quantum = spread.quantum;
  if (!spread.spacingMatters()) return result;
  values = CoordinateValues();
  // The points where they lie when all are finite (a 10M-point cloud's copy is 120 MB).
  static_assert(sizeof(pcl::PointXYZ) == 4 * sizeof(float), "x, y, z every four floats");
  if (finite.size() == cloud.size()) {
    result.median_spacing = medianSpacing(cloud[0].data, 4, cloud.size(), samples);
    return result;
  }
  std::vector<float> xyz;
  xyz.reserve(3 * finite.size());
  for (const pcl::index_t i : finite) xyz.insert(xyz.end(), {cloud[i].x, cloud[i].y, cloud[i].z});
  result.median_spacing = medianSpacing(xyz, samples);
  return result;
}

RadiusNeighbourCounts countRadiusNeighbours(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                            double radius, int min_neighbours, int samples) {
  if (!(radius > 0.0) || !std::isfinite(radius) || min_neighbours < 1)
    throw pcl::BadArgumentException("countRadiusNeighbours: radius > 0 and min_neighbours >= 1");
  RadiusNeighbourCounts result;
  const std::vector<pcl::index_t> finite = finitePoints(cloud);
  if (finite.empty()) return result;
  const detail::PointKdTree tree = treeOf(cloud, finite);
  std::vector<std::int64_t> counts;
  std::vector<double> reach;
  pcl::Indices found;
  std::vector<float> distances;
  for (const pcl::index_t i : sample(finite, samples)) {
    counts.push_back(tree.withinRadius(cloud[i].data, radius, found, distances, 0, false));
    if (tree.nearestK(cloud[i].data, min_neighbours, found, distances) == min_neighbours)
      reach.push_back(std::sqrt(static_cast<double>(distances.back())));
  }
  result.sampled = static_cast<std::int64_t>(counts.size());
  result.min = *std::min_element(counts.begin(), counts.end());
  result.median = median(counts);
  result.share_under_3 = static_cast<double>(std::count_if(counts.begin(), counts.end(),
                                                           [](std::int64_t c) { return c < 3; })) /
                         static_cast<double>(counts.size());
  if (!reach.empty()) {
    const std::size_t at = std::min(reach.size() - 1, (reach.size() * 9) / 10);
    std::nth_element(reach.begin(), reach.begin() + at, reach.end());
    result.radius_for_min_neighbours = reach[at];
  }
  return result;
}

}  // namespace pcl_ddg
