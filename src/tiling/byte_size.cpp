#include "pcl_ddg/tiling/byte_size.h"

#include <pcl/exceptions.h>

#include <cctype>
#include <charconv>
#include <cmath>

namespace pcl_ddg {

std::uint64_t parseByteSize(const std::string& text) {
  const auto refuse = [&]() -> std::uint64_t {
    throw pcl::BadArgumentException("a size like 2G, 512M or 64k, not '" + text + "'");
  };
  std::size_t begin = 0, end = text.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(text[begin]))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
  double value = 0.0;
  // from_chars: no sign, no hexadecimal, no locale; "inf" and "nan" fail the checks below.
  const auto [stop, error] = std::from_chars(text.data() + begin, text.data() + end, value);
  if (error != std::errc() || stop == text.data() + begin) return refuse();
  std::string unit(stop, text.data() + end);
  if (unit.size() >= 2 && (unit.compare(unit.size() - 2, 2, "iB") == 0)) {
    unit.resize(unit.size() - 2);
    if (unit.empty()) return refuse();  // "iB" names a unit's multiple, not bytes
  } else if (unit.size() >= 2 && unit.back() == 'B') {
    unit.pop_back();  // "GB", "kB": the unit's bytes
  }
  double scale = -1.0;
  if (unit.empty() || unit == "B") scale = 1.0;
  if (unit == "k" || unit == "K") scale = 1024.0;
  if (unit == "m" || unit == "M") scale = 1024.0 * 1024.0;
  if (unit == "g" || unit == "G") scale = 1024.0 * 1024.0 * 1024.0;
  if (unit == "t" || unit == "T") scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  const double bytes = value * scale;
  if (scale < 0.0 || !(value > 0.0) || !std::isfinite(bytes) || bytes > 1e18) return refuse();
  return static_cast<std::uint64_t>(bytes);
}

}  // namespace pcl_ddg
