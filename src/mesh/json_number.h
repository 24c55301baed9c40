#pragma once
// JSON text for a double: shortest round-trip digits, null for NaN or infinity.
#include <charconv>
#include <cmath>
#include <string>

#include <Eigen/Core>

namespace pcl_ddg {
namespace detail {

/** The shortest decimal text that reads back as v exactly (std::to_chars). */
inline std::string shortestNumber(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

inline std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  return shortestNumber(v);
}

inline std::string jsonArray(const Eigen::Vector3d& v) {
  return "[" + jsonNumber(v[0]) + ", " + jsonNumber(v[1]) + ", " + jsonNumber(v[2]) + "]";
}

}  // namespace detail
}  // namespace pcl_ddg
