#include "pcl_ddg/mesh/cloud_report.h"

#include <boost/sort/spreadsort/integer_sort.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <sstream>
#include <vector>

#include "json_number.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace {

std::uint64_t mixed(std::uint64_t v) {  // splitmix64's finaliser
  v = (v ^ (v >> 30)) * 0xbf58476d1ce4e5b9ull;
  v = (v ^ (v >> 27)) * 0x94d049bb133111ebull;
  return v ^ (v >> 31);
}

// Of the three coordinates' values: +0.0 and -0.0 (equal coordinates) hash alike.
std::uint64_t hashOf(const Eigen::Vector3d& p) {
  std::uint64_t h = 0;
  for (int d = 0; d < 3; ++d) {
    const double v = p[d] + 0.0;
    std::uint64_t bits;
    std::memcpy(&bits, &v, 8);
    h = mixed(h ^ bits);
  }
  return h;
}

// Finite points equal to an earlier one, in linear time (the sort of every triple took 0.5 s for
// 10M points): the triples' hashes are sorted by radix, and only the points whose hash occurs
// more than once are compared coordinate by coordinate, so that a collision of two distinct
// triples is no duplicate.
std::int64_t countDuplicates(const PositionsRef& positions) {
  const auto n = static_cast<std::int64_t>(positions.cols());
  std::vector<std::uint64_t> hashes(static_cast<std::size_t>(n));
  std::int64_t non_finite = 0;
#pragma omp parallel for schedule(static) reduction(+ : non_finite) if (n > 100000)
  for (std::int64_t i = 0; i < n; ++i) {
    const bool finite = positions.col(i).allFinite();
    hashes[static_cast<std::size_t>(i)] = finite ? hashOf(positions.col(i)) : 0;
    non_finite += finite ? 0 : 1;
  }
  if (non_finite > 0) {  // (rare) the non-finite points' places are taken out
    std::size_t kept = 0;
    for (std::int64_t i = 0; i < n; ++i)
      if (positions.col(i).allFinite()) hashes[kept++] = hashes[static_cast<std::size_t>(i)];
    hashes.resize(kept);
  }
  boost::sort::spreadsort::integer_sort(hashes.begin(), hashes.end());
  std::vector<std::uint64_t> repeated;
  for (std::size_t k = 1; k < hashes.size(); ++k) {
    if (hashes[k] == hashes[k - 1] && (repeated.empty() || repeated.back() != hashes[k]))
      repeated.push_back(hashes[k]);
  }
  std::vector<std::uint64_t>().swap(hashes);
  if (repeated.empty()) return 0;
  std::vector<std::array<double, 3>> suspects;
#pragma omp parallel if (n > 100000)
  {
    std::vector<std::array<double, 3>> found;
#pragma omp for schedule(static) nowait
    for (std::int64_t i = 0; i < n; ++i) {
      const auto p = positions.col(i);
      if (p.allFinite() && std::binary_search(repeated.begin(), repeated.end(), hashOf(p)))
        found.push_back({p[0], p[1], p[2]});
    }
#pragma omp critical
    suspects.insert(suspects.end(), found.begin(), found.end());
  }
  std::sort(suspects.begin(), suspects.end());
  return suspects.end() - std::unique(suspects.begin(), suspects.end());
}

}  // namespace

CloudReport makeCloudReport(const pcl::PCLPointCloud2& cloud, const PositionsRef& positions) {
  if (positions.cols() != static_cast<Eigen::Index>(cloud.width) * cloud.height)
    throw InvalidMeshException("makeCloudReport: " + std::to_string(positions.cols()) +
                               " positions for a cloud of " + std::to_string(cloud.width) + " x " +
                               std::to_string(cloud.height) + " points");
  CloudReport r;
  r.width = cloud.width;
  r.height = cloud.height;
  r.points = positions.cols();
  r.nan_points = findNonFiniteVertices(positions).count;
  r.duplicate_points = countDuplicates(positions);
  r.bounding_box = boundingBox(positions);
  return r;
}

std::string CloudReport::toJson() const {
  std::ostringstream out;
  out << "{\"points\": " << points << ", \"width\": " << width << ", \"height\": " << height
      << ", \"organized\": " << (organized() ? "true" : "false")
      << ", \"nan_points\": " << nan_points << ", \"duplicate_points\": " << duplicate_points;
  out << ", \"bounding_box_min\": " << detail::jsonArray(bounding_box.min)
      << ", \"bounding_box_max\": " << detail::jsonArray(bounding_box.max) << "}";
  return out.str();
}

namespace {

std::string box(const BoundingBox& b) {
  if (!b.min.allFinite()) return "none (no finite point)";
  return detail::textArray(b.min) + " .. " + detail::textArray(b.max);
}

}  // namespace

std::string CloudReport::toText() const {
  std::ostringstream out;
  out << "points:            " << points << "\n"
      << "layout:            " << width << " x " << height
      << (organized() ? " (organized)" : " (unorganized)") << "\n"
      << "NaN points:        " << nan_points << "\n"
      << "duplicate points:  " << duplicate_points << "\n"
      << "bounding box:      " << box(bounding_box) << "\n";
  return out.str();
}

}  // namespace pcl_ddg
