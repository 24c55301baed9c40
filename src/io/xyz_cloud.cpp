#include "xyz_cloud.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl_ddg {
namespace detail {
namespace {

bool fitsFloat(double v) {
  // (beyond float's range the cast itself would be undefined)
  return !std::isfinite(v) || (std::abs(v) <= std::numeric_limits<float>::max() &&
                               static_cast<double>(static_cast<float>(v)) == v);
}

double coordinate(const pcl::PCLPointCloud2& cloud, std::size_t at) {
  double v;
  std::memcpy(&v, cloud.data.data() + 8 * at, 8);
  return v;
}

}  // namespace

pcl::PCLPointCloud2 doubleXYZCloud(std::size_t points) {
  pcl::PCLPointCloud2 cloud;
  cloud.width = static_cast<std::uint32_t>(points);
  cloud.height = 1;
  for (std::uint32_t d = 0; d < 3; ++d) {
    pcl::PCLPointField field;
    field.name = std::string(1, static_cast<char>('x' + d));
    field.offset = d * 8;
    field.datatype = pcl::PCLPointField::FLOAT64;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.point_step = 24;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.data.resize(24 * points);
  return cloud;
}

void narrowXYZCloud(pcl::PCLPointCloud2& cloud) {
  const std::size_t values = 3 * static_cast<std::size_t>(cloud.width) * cloud.height;
  bool fits_float = true, dense = true;
  for (std::size_t at = 0; at < values; ++at) {
    const double v = coordinate(cloud, at);
    fits_float = fits_float && fitsFloat(v);
    dense = dense && std::isfinite(v);
  }
  cloud.is_dense = dense;
  if (!fits_float) return;
  // Front to back: value `at` moves from byte 8 at to byte 4 at, never past one still unread.
  for (std::size_t at = 0; at < values; ++at) {
    const auto f = static_cast<float>(coordinate(cloud, at));
    std::memcpy(cloud.data.data() + 4 * at, &f, 4);
  }
  cloud.data.resize(4 * values);
  for (std::uint32_t d = 0; d < 3; ++d) {
    cloud.fields[d].offset = d * 4;
    cloud.fields[d].datatype = pcl::PCLPointField::FLOAT32;
  }
  cloud.point_step = 12;
  cloud.row_step = cloud.point_step * cloud.width;
}

pcl::PCLPointCloud2 makeXYZCloud(const std::vector<double>& xyz) {
  pcl::PCLPointCloud2 cloud = doubleXYZCloud(xyz.size() / 3);
  if (!xyz.empty()) std::memcpy(cloud.data.data(), xyz.data(), 8 * xyz.size());
  narrowXYZCloud(cloud);
  return cloud;
}

}  // namespace detail
}  // namespace pcl_ddg
