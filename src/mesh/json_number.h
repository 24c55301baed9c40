#pragma once
// JSON text for a double: shortest round-trip digits, null for NaN or infinity.
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>

#include <Eigen/Core>

namespace pcl_ddg {
namespace detail {

inline std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream out;
  out << std::setprecision(std::numeric_limits<double>::max_digits10) << v;
  return out.str();
}

inline std::string jsonArray(const Eigen::Vector3d& v) {
  return "[" + jsonNumber(v[0]) + ", " + jsonNumber(v[1]) + ", " + jsonNumber(v[2]) + "]";
}

}  // namespace detail
}  // namespace pcl_ddg
