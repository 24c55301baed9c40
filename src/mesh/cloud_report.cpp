#include "pcl_ddg/mesh/cloud_report.h"

#include <algorithm>
#include <array>
#include <sstream>
#include <vector>

#include "json_number.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {

CloudReport makeCloudReport(const pcl::PCLPointCloud2& cloud) {
  CloudReport r;
  r.width = cloud.width;
  r.height = cloud.height;
  const Eigen::Matrix3Xd p = vertexPositions(cloud, NonFinitePolicy::Keep);
  r.points = p.cols();
  r.nan_points = findNonFiniteVertices(p).count;
  std::vector<std::array<double, 3>> finite;
  finite.reserve(static_cast<std::size_t>(p.cols()));
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    if (p.col(i).allFinite()) finite.push_back({p(0, i), p(1, i), p(2, i)});
  }
  std::sort(finite.begin(), finite.end());
  r.duplicate_points = finite.end() - std::unique(finite.begin(), finite.end());
  r.bounding_box = boundingBox(p);
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

// Every digit: UTM coordinates differ in the last places a default stream would drop.
std::string box(const Eigen::Vector3d& corner) {
  return "[" + detail::shortestNumber(corner.x()) + " " + detail::shortestNumber(corner.y()) + " " +
         detail::shortestNumber(corner.z()) + "]";
}

}  // namespace

std::string CloudReport::toText() const {
  std::ostringstream out;
  out << "points:            " << points << "\n"
      << "layout:            " << width << " x " << height
      << (organized() ? " (organized)" : " (unorganized)") << "\n"
      << "NaN points:        " << nan_points << "\n"
      << "duplicate points:  " << duplicate_points << "\n"
      << "bounding box:      " << box(bounding_box.min) << " .. " << box(bounding_box.max) << "\n";
  return out.str();
}

}  // namespace pcl_ddg
