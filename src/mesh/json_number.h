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

/** shortestNumber's digits, in fixed notation over the range coordinates take (5000000, not
 *  5e+06): the text reports' numbers. */
inline std::string textNumber(double v) {
  char text[48];
  const double a = std::abs(v);
  const auto end = a >= 1e-5 && a < 1e15
                       ? std::to_chars(text, text + sizeof text, v, std::chars_format::fixed).ptr
                       : std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

/** "[x y z]" in textNumber's digits: UTM coordinates differ in the last places a default stream
 *  would drop. */
inline std::string textArray(const Eigen::Vector3d& v) {
  return "[" + textNumber(v[0]) + " " + textNumber(v[1]) + " " + textNumber(v[2]) + "]";
}

}  // namespace detail
}  // namespace pcl_ddg
