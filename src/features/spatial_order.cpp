#include "pcl_ddg/features/spatial_order.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

namespace pcl_ddg {
namespace detail {
namespace {

// The bits of v spread to every third position (v < 2^10).
std::uint32_t spreadBits(std::uint32_t v) {
  v = (v | (v << 16)) & 0x030000FFu;
  v = (v | (v << 8)) & 0x0300F00Fu;
  v = (v | (v << 4)) & 0x030C30C3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

}  // namespace

std::vector<int> spatialOrder(const std::vector<Eigen::Vector3f>& points) {
  const int n = static_cast<int>(points.size());
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  int finite = 0;
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    ++finite;
  }
  std::vector<int> order(points.size());
  if (finite < 2) {
    std::iota(order.begin(), order.end(), 0);
    std::stable_partition(order.begin(), order.end(), [&](int i) { return points[i].allFinite(); });
    return order;
  }
  // About eight points per cell of the bounding cube, 2 to 128 cells per axis.
  const int bits =
      std::clamp(static_cast<int>(std::ceil(std::log2(std::cbrt(finite / 8.0)))), 1, 7);
  const int cells_per_axis = 1 << bits;
  const double extent = std::max(1e-30, static_cast<double>((hi - lo).maxCoeff()));
  const double scale = cells_per_axis / extent;
  const std::uint32_t cells = 1u << (3 * bits);
  std::vector<std::uint32_t> code(points.size(), cells);  // non-finite: past the last cell
  std::vector<int> start(cells + 2, 0);
  for (int i = 0; i < n; ++i) {
    if (points[i].allFinite()) {
      std::uint32_t c[3];
      for (int d = 0; d < 3; ++d) {
        const double at = std::floor((points[i][d] - lo[d]) * scale);
        c[d] = static_cast<std::uint32_t>(std::clamp(at, 0.0, cells_per_axis - 1.0));
      }
      code[i] = spreadBits(c[0]) | spreadBits(c[1]) << 1 | spreadBits(c[2]) << 2;
    }
    ++start[code[i] + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  for (int i = 0; i < n; ++i) order[start[code[i]]++] = i;
  return order;
}

}  // namespace detail
}  // namespace pcl_ddg
