#include "pcl_ddg/mesh/cloud_report.h"

#include <algorithm>
#include <array>
#include <sstream>
#include <vector>

#include "json_number.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {

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
  std::vector<std::array<double, 3>> finite;
  finite.reserve(static_cast<std::size_t>(positions.cols()));
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    const auto p = positions.col(i);
    if (p.allFinite()) finite.push_back({p[0], p[1], p[2]});
  }
  std::sort(finite.begin(), finite.end());
  r.duplicate_points = finite.end() - std::unique(finite.begin(), finite.end());
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
