#include "pcl_ddg/mesh/vertex_positions.h"

#include <pcl/PCLPointField.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>

#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {
namespace {

template <typename T>
double load(const std::uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return static_cast<double>(value);
}

double readScalar(const std::uint8_t* p, std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return load<std::int8_t>(p);
    case pcl::PCLPointField::UINT8:
      return load<std::uint8_t>(p);
    case pcl::PCLPointField::INT16:
      return load<std::int16_t>(p);
    case pcl::PCLPointField::UINT16:
      return load<std::uint16_t>(p);
    case pcl::PCLPointField::INT32:
      return load<std::int32_t>(p);
    case pcl::PCLPointField::UINT32:
      return load<std::uint32_t>(p);
    case pcl::PCLPointField::FLOAT32:
      return load<float>(p);
    case pcl::PCLPointField::FLOAT64:
      return load<double>(p);
    default:
      throw InvalidMeshException("unsupported vertex field type");
  }
}

const pcl::PCLPointField& namedField(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return f;
  }
  std::string existing;
  for (const auto& f : cloud.fields) existing += (existing.empty() ? "" : " ") + f.name;
  throw InvalidMeshException("vertex data has no '" + name + "' field (it has: " +
                             (existing.empty() ? std::string("no fields") : existing) + ")");
}

template <typename T>
void store(std::uint8_t* p, T value) {
  std::memcpy(p, &value, sizeof(T));
}

}  // namespace

float floatFieldValue(double value, const std::string& field, std::size_t vertex) {
  if (std::isfinite(value) && std::abs(value) > std::numeric_limits<float>::max()) {
    std::ostringstream text;
    text << "vertex " << vertex << ": " << field << " = " << value
         << " does not fit a float field (write double precision, or a smaller step)";
    throw InvalidMeshException(text.str());
  }
  return static_cast<float>(value);
}

NonFiniteVertices findNonFiniteVertices(const PositionsRef& positions) {
  NonFiniteVertices result;
  Eigen::Index first = positions.cols();
  std::int64_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count) reduction(min : first)
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    if (positions.col(i).allFinite()) continue;
    first = std::min(first, i);
    ++count;
  }
  if (count > 0) result.first = first;
  result.count = count;
  return result;
}

void requireFinite(const PositionsRef& positions) {
  const NonFiniteVertices bad = findNonFiniteVertices(positions);
  if (bad.count == 0) return;
  std::ostringstream msg;
  msg << "vertex " << bad.first << " has a non-finite coordinate (" << bad.count
      << " such vertices)";
  throw InvalidMeshException(msg.str());
}

bool hasVertexField(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return true;
  }
  return false;
}

Eigen::VectorXd vertexScalarField(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (cloud.data.size() < n * cloud.point_step) {
    throw InvalidMeshException("vertex data is shorter than width x height x point_step");
  }
  const pcl::PCLPointField& field = namedField(cloud, name);
  Eigen::VectorXd values(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    values[static_cast<Eigen::Index>(i)] =
        readScalar(cloud.data.data() + i * cloud.point_step + field.offset, field.datatype);
  }
  return values;
}

Eigen::Matrix3Xd vertexPositions(const pcl::PCLPointCloud2& cloud, NonFinitePolicy policy) {
  if (cloud.width * cloud.height == 0) throw InvalidMeshException("mesh has no vertices");
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (cloud.data.size() < n * cloud.point_step) {
    throw InvalidMeshException("vertex data is shorter than width x height x point_step");
  }
  const pcl::PCLPointField* fields[3] = {&namedField(cloud, "x"), &namedField(cloud, "y"),
                                         &namedField(cloud, "z")};
  // One pass, serial: loaders run in forked children (tests, services), where an OpenMP team
  // inherited from the parent would hang.
  Eigen::Matrix3Xd positions(3, static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* point = cloud.data.data() + i * cloud.point_step;
    for (int axis = 0; axis < 3; ++axis) {
      positions(axis, static_cast<Eigen::Index>(i)) =
          readScalar(point + fields[axis]->offset, fields[axis]->datatype);
    }
  }
  if (policy == NonFinitePolicy::Throw) requireFinite(positions);
  return positions;
}

void setVertexPositions(pcl::PCLPointCloud2& cloud, const Eigen::Matrix3Xd& positions) {
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (static_cast<std::size_t>(positions.cols()) != n || cloud.data.size() < n * cloud.point_step) {
    throw InvalidMeshException("positions do not match the vertex data");
  }
  const char* names[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const pcl::PCLPointField& field = namedField(cloud, names[axis]);
    if (field.datatype != pcl::PCLPointField::FLOAT32 &&
        field.datatype != pcl::PCLPointField::FLOAT64) {
      throw InvalidMeshException(std::string("cannot write positions into an integer '") +
                                 names[axis] + "' field");
    }
    for (std::size_t i = 0; i < n; ++i) {
      std::uint8_t* p = cloud.data.data() + i * cloud.point_step + field.offset;
      const double value = positions(axis, static_cast<Eigen::Index>(i));
      if (field.datatype == pcl::PCLPointField::FLOAT32) {
        store<float>(p, floatFieldValue(value, names[axis], i));
      } else {
        store<double>(p, value);
      }
    }
  }
}

}  // namespace pcl_ddg
