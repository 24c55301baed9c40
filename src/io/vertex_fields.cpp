#include "pcl_ddg/io/vertex_fields.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include <pcl/common/io.h>
#include <pcl/exceptions.h>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace {

std::size_t pointCount(const pcl::PCLPointCloud2& cloud) {
  return static_cast<std::size_t>(cloud.width) * cloud.height;
}

// Rewrites every row of cloud.data as new_step bytes, fill(old_row, new_row) making each. In
// place when the vector's capacity holds the new rows (readMeshFile reserves it for the fields a
// tool adds): no second copy of the cloud. Rows then move back to front when they grow and front
// to back when they shrink, so that a row's new place covers only rows already moved and its
// own old bytes, which fill reads from a copy.
template <typename Fill>
void relayout(pcl::PCLPointCloud2& cloud, std::uint32_t new_step, Fill fill) {
  const std::size_t n = pointCount(cloud);
  const std::uint32_t old_step = cloud.point_step;
  if (old_step == 0) {  // no bytes to keep (and no row to copy from)
    cloud.data.assign(n * new_step, 0);
  } else if (new_step <= old_step || cloud.data.capacity() >= n * new_step) {
    std::vector<std::uint8_t> row(old_step);
    std::uint8_t* data = nullptr;
    if (new_step > old_step) {
      cloud.data.resize(n * new_step);  // within the capacity: the same block
      data = cloud.data.data();
      for (std::size_t i = n; i-- > 0;) {
        std::memcpy(row.data(), data + i * old_step, old_step);
        fill(row.data(), data + i * new_step);
      }
    } else {
      data = cloud.data.data();
      for (std::size_t i = 0; i < n; ++i) {
        std::memcpy(row.data(), data + i * old_step, old_step);
        fill(row.data(), data + i * new_step);
      }
      cloud.data.resize(n * new_step);
    }
  } else {
    std::vector<std::uint8_t> data(n * new_step);
    const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) if (count > 100000)
    for (std::int64_t i = 0; i < count; ++i) {
      fill(cloud.data.data() + static_cast<std::size_t>(i) * old_step,
           data.data() + static_cast<std::size_t>(i) * new_step);
    }
    cloud.data.swap(data);
  }
  cloud.point_step = new_step;
  cloud.row_step = new_step * cloud.width;
}

// Appends uninitialised scalar fields of one type in a single new layout; returns the offset of
// the first (the others follow it).
std::uint32_t appendFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                           std::uint8_t datatype) {
  const std::uint32_t size = pcl::getFieldSize(datatype);
  const std::uint32_t old_step = cloud.point_step;
  const std::uint32_t new_step = old_step + size * static_cast<std::uint32_t>(names.size());
  relayout(cloud, new_step, [old_step](const std::uint8_t* from, std::uint8_t* to) {
    std::memcpy(to, from, old_step);
  });
  for (std::size_t k = 0; k < names.size(); ++k) {
    pcl::PCLPointField field;
    field.name = names[k];
    field.offset = old_step + size * static_cast<std::uint32_t>(k);
    field.datatype = datatype;
    field.count = 1;
    cloud.fields.push_back(field);
  }
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
  relayout(cloud, old_step - size, [=](const std::uint8_t* from, std::uint8_t* to) {
    std::memcpy(to, from, begin);
    std::memcpy(to + begin, from + begin + size, old_step - begin - size);
  });
  cloud.fields.erase(it);
  for (auto& f : cloud.fields) {
    if (f.offset > begin) f.offset -= size;
  }
  return true;
}

namespace {

// setVertexFields of doubles or floats (read where they lie: no copy into a matrix of doubles).
template <typename Values>
void writeFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                 const Values& values, FieldPrecision precision) {
  const std::size_t n = pointCount(cloud);
  if (static_cast<std::size_t>(values.rows()) != names.size() ||
      static_cast<std::size_t>(values.cols()) != n) {
    throw pcl::BadArgumentException(
        std::to_string(values.rows()) + " x " + std::to_string(values.cols()) + " values for " +
        std::to_string(names.size()) + " fields of " + std::to_string(n) + " vertices");
  }
  for (const std::string& name : names) removeVertexField(cloud, name);
  const bool as_double = precision == FieldPrecision::Double;
  const std::uint32_t first_offset = appendFields(
      cloud, names, as_double ? pcl::PCLPointField::FLOAT64 : pcl::PCLPointField::FLOAT32);
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::uint32_t offset = first_offset + static_cast<std::uint32_t>(k) * (as_double ? 8 : 4);
    const Eigen::Index row = static_cast<Eigen::Index>(k);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint8_t* dst = cloud.data.data() + i * cloud.point_step + offset;
      const double value = values(row, static_cast<Eigen::Index>(i));
      if (as_double) {
        std::memcpy(dst, &value, 8);
      } else {
        const float v = floatFieldValue(value, names[k], i);
        std::memcpy(dst, &v, 4);
      }
    }
  }
}

}  // namespace

void addVertexFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                     FieldPrecision precision) {
  for (const std::string& name : names) removeVertexField(cloud, name);
  const bool as_double = precision == FieldPrecision::Double;
  const std::uint32_t first_offset = appendFields(
      cloud, names, as_double ? pcl::PCLPointField::FLOAT64 : pcl::PCLPointField::FLOAT32);
  const std::size_t bytes = names.size() * (as_double ? 8 : 4);
  std::vector<std::uint8_t> nan_row(bytes);
  for (std::size_t at = 0; at < bytes; at += as_double ? 8 : 4) {
    if (as_double) {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      std::memcpy(nan_row.data() + at, &nan, 8);
    } else {
      const float nan = std::numeric_limits<float>::quiet_NaN();
      std::memcpy(nan_row.data() + at, &nan, 4);
    }
  }
  const std::size_t n = pointCount(cloud);
  for (std::size_t i = 0; i < n; ++i)
    std::memcpy(cloud.data.data() + i * cloud.point_step + first_offset, nan_row.data(), bytes);
}

void setVertexFieldSlice(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                         std::size_t first,
                         const Eigen::Ref<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>& values) {
  const std::size_t count = static_cast<std::size_t>(values.cols());
  if (static_cast<std::size_t>(values.rows()) != names.size() || first > pointCount(cloud) ||
      count > pointCount(cloud) - first)
    throw pcl::BadArgumentException(
        "a slice of " + std::to_string(values.rows()) + " x " + std::to_string(count) +
        " values from point " + std::to_string(first) + " for " + std::to_string(names.size()) +
        " fields of " + std::to_string(pointCount(cloud)) + " vertices");
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto field =
        std::find_if(cloud.fields.begin(), cloud.fields.end(),
                     [&](const pcl::PCLPointField& f) { return f.name == names[k]; });
    if (field == cloud.fields.end() || (field->datatype != pcl::PCLPointField::FLOAT32 &&
                                        field->datatype != pcl::PCLPointField::FLOAT64))
      throw pcl::BadArgumentException("no float or double field " + names[k] + " to write");
    const bool as_double = field->datatype == pcl::PCLPointField::FLOAT64;
    std::uint8_t* dst = cloud.data.data() + first * cloud.point_step + field->offset;
    for (std::size_t j = 0; j < count; ++j, dst += cloud.point_step) {
      const float v = values(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j));
      if (as_double) {
        const double d = v;
        std::memcpy(dst, &d, 8);
      } else {
        std::memcpy(dst, &v, 4);
      }
    }
  }
}

void setVertexField(pcl::PCLPointCloud2& cloud, const std::string& name,
                    const Eigen::VectorXd& values, FieldPrecision precision) {
  writeFields(cloud, {name}, Eigen::Map<const Eigen::MatrixXd>(values.data(), 1, values.size()),
              precision);
}

void setVertexFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                     const Eigen::Ref<const Eigen::MatrixXd>& values, FieldPrecision precision) {
  writeFields(cloud, names, values, precision);
}

void setVertexFields(pcl::PCLPointCloud2& cloud, const std::vector<std::string>& names,
                     const Eigen::Ref<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>& values,
                     FieldPrecision precision) {
  writeFields(cloud, names, values, precision);
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
    const std::uint32_t old_step = cloud.point_step;
    relayout(cloud, old_step + 3 * size, [=](const std::uint8_t* from, std::uint8_t* to) {
      std::memcpy(to + 3 * size, from, old_step);
    });
    for (auto& f : cloud.fields) f.offset += 3 * size;
    for (std::uint32_t d = 0; d < 3; ++d) {
      pcl::PCLPointField field;
      field.name = std::string(1, static_cast<char>('x' + d));
      field.offset = d * size;
      field.datatype = datatype;
      field.count = 1;
      cloud.fields.insert(cloud.fields.begin() + d, field);
    }
  }
  setVertexPositions(cloud, positions);
}

void setVertexColors(pcl::PCLPointCloud2& cloud, const VertexColors& rgb, ColorLayout layout) {
  const std::size_t n = pointCount(cloud);
  if (static_cast<std::size_t>(rgb.cols()) != n) {
    throw pcl::BadArgumentException("colour count does not match the vertex count");
  }
  for (const char* name : {"rgb", "rgba", "red", "green", "blue", "alpha"}) {
    removeVertexField(cloud, name);
  }
  if (layout == ColorLayout::PackedRGB) {
    const std::uint32_t offset = appendFields(cloud, {"rgb"}, pcl::PCLPointField::FLOAT32);
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = rgb.col(static_cast<Eigen::Index>(i));
      const std::uint32_t packed =
          0xff000000u | std::uint32_t{c[0]} << 16 | std::uint32_t{c[1]} << 8 | std::uint32_t{c[2]};
      std::memcpy(cloud.data.data() + i * cloud.point_step + offset, &packed, 4);
    }
    return;
  }
  const std::uint32_t offset =
      appendFields(cloud, {"red", "green", "blue"}, pcl::PCLPointField::UINT8);
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      cloud.data[i * cloud.point_step + offset + c] = rgb(c, static_cast<Eigen::Index>(i));
    }
  }
}

namespace {

const pcl::PCLPointField* packedColorField(const pcl::PCLPointCloud2& cloud) {
  for (const auto& f : cloud.fields) {
    if ((f.name == "rgb" || f.name == "rgba") && pcl::getFieldSize(f.datatype) == 4 && f.count == 1)
      return &f;
  }
  return nullptr;
}

}  // namespace

std::optional<ColorLayout> vertexColorLayout(const pcl::PCLPointCloud2& cloud) {
  if (hasVertexField(cloud, "red") && hasVertexField(cloud, "green") &&
      hasVertexField(cloud, "blue"))
    return ColorLayout::Channels;
  if (packedColorField(cloud)) return ColorLayout::PackedRGB;
  return std::nullopt;
}

VertexColors vertexColors(const pcl::PCLPointCloud2& cloud) {
  const auto layout = vertexColorLayout(cloud);
  if (!layout) throw InvalidMeshException("the vertices have no colours (red green blue or rgb)");
  const std::size_t n = pointCount(cloud);
  VertexColors rgb(3, static_cast<Eigen::Index>(n));
  if (*layout == ColorLayout::Channels) {
    const char* names[3] = {"red", "green", "blue"};
    Eigen::MatrixXd values(3, static_cast<Eigen::Index>(n));
    for (int c = 0; c < 3; ++c) values.row(c) = vertexScalarField(cloud, names[c]).transpose();
    // 16-bit channels (LAS) hold 0..65535; some writers put 8-bit values in them, so they are
    // scaled down only when a value exceeds 255.
    const bool sixteen_bits =
        std::all_of(names, names + 3,
                    [&](const char* name) {
                      return std::any_of(cloud.fields.begin(), cloud.fields.end(),
                                         [&](const pcl::PCLPointField& f) {
                                           return f.name == name &&
                                                  f.datatype == pcl::PCLPointField::UINT16;
                                         });
                    }) &&
        n > 0 && values.maxCoeff() > 255.0;
    if (sixteen_bits) values /= 257.0;
    // Channels stored wider than uchar (e.g. float 0..255) are clamped, not wrapped.
    rgb = values.array().cwiseMax(0.0).cwiseMin(255.0).round().cast<std::uint8_t>();
    return rgb;
  }
  const std::uint32_t offset = packedColorField(cloud)->offset;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t packed = 0;
    std::memcpy(&packed, cloud.data.data() + i * cloud.point_step + offset, 4);
    rgb.col(static_cast<Eigen::Index>(i)) << static_cast<std::uint8_t>(packed >> 16),
        static_cast<std::uint8_t>(packed >> 8), static_cast<std::uint8_t>(packed);
  }
  return rgb;
}

}  // namespace pcl_ddg
