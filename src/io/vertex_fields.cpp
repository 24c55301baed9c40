#include "pcl_ddg/io/vertex_fields.h"

#include <algorithm>
#include <cstring>

#include <pcl/common/io.h>
#include <pcl/exceptions.h>

#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace {

std::size_t pointCount(const pcl::PCLPointCloud2& cloud) {
  return static_cast<std::size_t>(cloud.width) * cloud.height;
}

// Appends an uninitialised scalar field of `size` bytes and returns its offset.
std::uint32_t appendField(pcl::PCLPointCloud2& cloud, const std::string& name,
                          std::uint8_t datatype, std::uint32_t size) {
  const std::size_t n = pointCount(cloud);
  const std::uint32_t old_step = cloud.point_step;
  const std::uint32_t new_step = old_step + size;
  std::vector<std::uint8_t> data(n * new_step, 0);
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(data.data() + i * new_step, cloud.data.data() + i * old_step, old_step);
  }
  pcl::PCLPointField field;
  field.name = name;
  field.offset = old_step;
  field.datatype = datatype;
  field.count = 1;
  cloud.fields.push_back(field);
  cloud.data.swap(data);
  cloud.point_step = new_step;
  cloud.row_step = new_step * cloud.width;
  return old_step;
}

}  // namespace

bool removeVertexField(pcl::PCLPointCloud2& cloud, const std::string& name) {
  const auto it = std::find_if(cloud.fields.begin(), cloud.fields.end(),
                               [&](const pcl::PCLPointField& f) { return f.name == name; });
  if (it == cloud.fields.end()) return false;
  const std::uint32_t begin = it->offset;
  const std::uint32_t size =
      pcl::getFieldSize(it->datatype) * std::max<std::uint32_t>(1, it->count);
  const std::uint32_t old_step = cloud.point_step;
  const std::uint32_t new_step = old_step - size;
  const std::size_t n = pointCount(cloud);
  std::vector<std::uint8_t> data(n * new_step);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* src = cloud.data.data() + i * old_step;
    std::uint8_t* dst = data.data() + i * new_step;
    std::memcpy(dst, src, begin);
    std::memcpy(dst + begin, src + begin + size, old_step - begin - size);
  }
  cloud.fields.erase(it);
  for (auto& f : cloud.fields) {
    if (f.offset > begin) f.offset -= size;
  }
  cloud.data.swap(data);
  cloud.point_step = new_step;
  cloud.row_step = new_step * cloud.width;
  return true;
}

void setVertexField(pcl::PCLPointCloud2& cloud, const std::string& name,
                    const Eigen::VectorXd& values, FieldPrecision precision) {
  const std::size_t n = pointCount(cloud);
  if (static_cast<std::size_t>(values.size()) != n) {
    throw pcl::BadArgumentException("field '" + name + "' has " + std::to_string(values.size()) +
                                    " values for " + std::to_string(n) + " vertices");
  }
  removeVertexField(cloud, name);
  const bool as_double = precision == FieldPrecision::Double;
  const std::uint32_t offset = appendField(
      cloud, name, as_double ? pcl::PCLPointField::FLOAT64 : pcl::PCLPointField::FLOAT32,
      as_double ? 8 : 4);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint8_t* dst = cloud.data.data() + i * cloud.point_step + offset;
    if (as_double) {
      const double v = values[static_cast<Eigen::Index>(i)];
      std::memcpy(dst, &v, 8);
    } else {
      const float v = floatFieldValue(values[static_cast<Eigen::Index>(i)], name, i);
      std::memcpy(dst, &v, 4);
    }
  }
}

void setVertexCoordinates(pcl::PCLPointCloud2& cloud, const Eigen::Matrix3Xd& positions,
                          FieldPrecision precision) {
  const std::uint8_t datatype = precision == FieldPrecision::Double ? pcl::PCLPointField::FLOAT64
                                                                    : pcl::PCLPointField::FLOAT32;
  if (static_cast<std::size_t>(positions.cols()) != pointCount(cloud))
    throw pcl::BadArgumentException("positions do not match the vertex count");
  const auto has_type = [&](const char* name) {
    return std::any_of(cloud.fields.begin(), cloud.fields.end(), [&](const pcl::PCLPointField& f) {
      return f.name == name && f.datatype == datatype && f.count == 1;
    });
  };
  if (!(has_type("x") && has_type("y") && has_type("z"))) {
    for (const char* axis : {"x", "y", "z"}) removeVertexField(cloud, axis);
    // The coordinates go first, where PCL's point types keep them.
    const std::uint32_t size = pcl::getFieldSize(datatype);
    const std::size_t n = pointCount(cloud);
    const std::uint32_t old_step = cloud.point_step;
    const std::uint32_t new_step = old_step + 3 * size;
    std::vector<std::uint8_t> data(n * new_step, 0);
    for (std::size_t i = 0; i < n; ++i) {
      std::memcpy(data.data() + i * new_step + 3 * size, cloud.data.data() + i * old_step,
                  old_step);
    }
    for (auto& f : cloud.fields) f.offset += 3 * size;
    for (std::uint32_t d = 0; d < 3; ++d) {
      pcl::PCLPointField field;
      field.name = std::string(1, static_cast<char>('x' + d));
      field.offset = d * size;
      field.datatype = datatype;
      field.count = 1;
      cloud.fields.insert(cloud.fields.begin() + d, field);
    }
    cloud.data.swap(data);
    cloud.point_step = new_step;
    cloud.row_step = new_step * cloud.width;
  }
  setVertexPositions(cloud, positions);
}

void setVertexColors(pcl::PCLPointCloud2& cloud,
                     const Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>& rgb) {
  const std::size_t n = pointCount(cloud);
  if (static_cast<std::size_t>(rgb.cols()) != n) {
    throw pcl::BadArgumentException("colour count does not match the vertex count");
  }
  for (const char* name : {"rgb", "rgba", "red", "green", "blue", "alpha"}) {
    removeVertexField(cloud, name);
  }
  const char* names[3] = {"red", "green", "blue"};
  for (int c = 0; c < 3; ++c) {
    const std::uint32_t offset = appendField(cloud, names[c], pcl::PCLPointField::UINT8, 1);
    for (std::size_t i = 0; i < n; ++i) {
      cloud.data[i * cloud.point_step + offset] = rgb(c, static_cast<Eigen::Index>(i));
    }
  }
}

}  // namespace pcl_ddg
