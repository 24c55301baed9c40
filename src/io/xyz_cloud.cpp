#include "xyz_cloud.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace pcl_ddg {
namespace detail {

pcl::PCLPointCloud2 makeXYZCloud(const std::vector<double>& xyz) {
  const bool fits_float = std::all_of(xyz.begin(), xyz.end(), [](double v) {
    // (beyond float's range the cast itself would be undefined)
    return !std::isfinite(v) || (std::abs(v) <= std::numeric_limits<float>::max() &&
                                 static_cast<double>(static_cast<float>(v)) == v);
  });
  const std::uint8_t datatype =
      fits_float ? pcl::PCLPointField::FLOAT32 : pcl::PCLPointField::FLOAT64;
  const std::uint32_t size = fits_float ? 4 : 8;

  pcl::PCLPointCloud2 cloud;
  cloud.width = static_cast<std::uint32_t>(xyz.size() / 3);
  cloud.height = 1;
  cloud.is_dense = std::all_of(xyz.begin(), xyz.end(), [](double v) { return std::isfinite(v); });
  for (std::uint32_t d = 0; d < 3; ++d) {
    pcl::PCLPointField field;
    field.name = std::string(1, static_cast<char>('x' + d));
    field.offset = d * size;
    field.datatype = datatype;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.point_step = 3 * size;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.data.resize(static_cast<std::size_t>(cloud.row_step));
  std::uint8_t* out = cloud.data.data();
  for (double v : xyz) {
    if (fits_float) {
      const float f = static_cast<float>(v);
      std::memcpy(out, &f, 4);
    } else {
      std::memcpy(out, &v, 8);
    }
    out += size;
  }
  return cloud;
}

}  // namespace detail
}  // namespace pcl_ddg
