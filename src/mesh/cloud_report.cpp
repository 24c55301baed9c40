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

}  // namespace

// Finite points equal to an earlier one, in linear time (the sort of every triple took 0.5 s for
// 10M points): the triples' hashes are sorted by radix, and only the points whose hash occurs
// more than once are compared coordinate by coordinate.
CloudReportBuilder::CloudReportBuilder(std::int64_t width, std::int64_t height) {
  report_.width = width;
  report_.height = height;
  if (width > 0 && height > 0) hashes_.reserve(static_cast<std::size_t>(width * height));
}

void CloudReportBuilder::count(const PositionsRef& piece) {
  const auto n = static_cast<std::int64_t>(piece.cols());
  const std::size_t first = hashes_.size();
  hashes_.resize(first + static_cast<std::size_t>(n));
  std::int64_t non_finite = 0;
#pragma omp parallel for schedule(static) reduction(+ : non_finite) if (n > 100000)
  for (std::int64_t i = 0; i < n; ++i) {
    const bool finite = piece.col(i).allFinite();
    hashes_[first + static_cast<std::size_t>(i)] = finite ? hashOf(piece.col(i)) : 0;
    non_finite += finite ? 0 : 1;
  }
  if (non_finite > 0) {  // (rare) the non-finite points' places are taken out
    std::size_t kept = first;
    for (std::int64_t i = 0; i < n; ++i)
      if (piece.col(i).allFinite()) hashes_[kept++] = hashes_[first + static_cast<std::size_t>(i)];
    hashes_.resize(kept);
  }
  const BoundingBox box = boundingBox(piece);
  if (box.min.allFinite()) bounds_.extend(Eigen::AlignedBox3d(box.min, box.max));
  report_.points += n;
  report_.nan_points += non_finite;
}

void CloudReportBuilder::compare(const PositionsRef& piece) {
  if (!comparing_) {
    comparing_ = true;
    boost::sort::spreadsort::integer_sort(hashes_.begin(), hashes_.end());
    for (std::size_t k = 1; k < hashes_.size(); ++k) {
      if (hashes_[k] == hashes_[k - 1] && (repeated_.empty() || repeated_.back() != hashes_[k]))
        repeated_.push_back(hashes_[k]);
    }
    std::vector<std::uint64_t>().swap(hashes_);
  }
  if (repeated_.empty()) return;
  const auto n = static_cast<std::int64_t>(piece.cols());
#pragma omp parallel if (n > 100000)
  {
    std::vector<std::array<double, 3>> found;
#pragma omp for schedule(static) nowait
    for (std::int64_t i = 0; i < n; ++i) {
      const auto p = piece.col(i);
      if (p.allFinite() && std::binary_search(repeated_.begin(), repeated_.end(), hashOf(p)))
        found.push_back({p[0], p[1], p[2]});
    }
#pragma omp critical
    suspects_.insert(suspects_.end(), found.begin(), found.end());
  }
}

CloudReport CloudReportBuilder::report() {
  CloudReport r = report_;
  std::sort(suspects_.begin(), suspects_.end());  // -0 and +0 are equal here, as in the hashes
  r.duplicate_points = suspects_.end() - std::unique(suspects_.begin(), suspects_.end());
  std::vector<std::array<double, 3>>().swap(suspects_);
  if (!bounds_.isEmpty()) {
    r.bounding_box.min = bounds_.min();
    r.bounding_box.max = bounds_.max();
  }
  return r;
}

CloudReport makeCloudReport(const pcl::PCLPointCloud2& cloud, const PositionsRef& positions) {
  if (positions.cols() != static_cast<Eigen::Index>(cloud.width) * cloud.height)
    throw InvalidMeshException("makeCloudReport: " + std::to_string(positions.cols()) +
                               " positions for a cloud of " + std::to_string(cloud.width) + " x " +
                               std::to_string(cloud.height) + " points");
  CloudReportBuilder builder(cloud.width, cloud.height);
  builder.count(positions);
  builder.compare(positions);
  return builder.report();
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
