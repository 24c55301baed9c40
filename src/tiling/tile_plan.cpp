#include "pcl_ddg/tiling/tile_plan.h"

#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace pcl_ddg {

PointHistogram::PointHistogram(const Eigen::AlignedBox3d& bounds, int resolution)
    : bounds_(bounds), resolution_(resolution) {
  if (resolution < 1 || resolution > 1024)
    throw pcl::BadArgumentException("the histogram resolution must be 1..1024");
  if (bounds.isEmpty() || !bounds.min().allFinite() || !bounds.max().allFinite())
    throw pcl::BadArgumentException("the histogram needs finite, non-empty bounds");
  const Eigen::Vector3d extent = bounds.sizes().cwiseMax(1e-300);
  cells_per_length_ = Eigen::Vector3d::Constant(resolution).cwiseQuotient(extent);
  counts_.assign(static_cast<std::size_t>(resolution) * resolution * resolution, 0);
}

int PointHistogram::cellOf(const Eigen::Vector3d& point) const {
  int cell = 0;
  for (int d = 2; d >= 0; --d) {
    const double at = std::floor((point[d] - bounds_.min()[d]) * cells_per_length_[d]);
    const int c = static_cast<int>(std::clamp(at, 0.0, static_cast<double>(resolution_ - 1)));
    cell = cell * resolution_ + c;
  }
  return cell;
}

namespace {

struct CellBox {
  Eigen::Vector3i first, end;
};

// Points per cell as a 3D prefix sum, so that any box of cells is counted in O(1).
class CellCounts {
 public:
  explicit CellCounts(const PointHistogram& h) : r_(h.resolution()) {
    const std::size_t side = static_cast<std::size_t>(r_) + 1;
    sum_.assign(side * side * side, 0);
    for (int z = 0; z < r_; ++z)
      for (int y = 0; y < r_; ++y)
        for (int x = 0; x < r_; ++x) {
          const std::int64_t c = h.counts()[(static_cast<std::size_t>(z) * r_ + y) * r_ + x];
          at(x + 1, y + 1, z + 1) = c + at(x, y + 1, z + 1) + at(x + 1, y, z + 1) +
                                    at(x + 1, y + 1, z) - at(x, y, z + 1) - at(x, y + 1, z) -
                                    at(x + 1, y, z) + at(x, y, z);
        }
  }
  std::int64_t count(const CellBox& b) const {
    const auto& l = b.first;
    const auto& h = b.end;
    return at(h.x(), h.y(), h.z()) - at(l.x(), h.y(), h.z()) - at(h.x(), l.y(), h.z()) -
           at(h.x(), h.y(), l.z()) + at(l.x(), l.y(), h.z()) + at(l.x(), h.y(), l.z()) +
           at(h.x(), l.y(), l.z()) - at(l.x(), l.y(), l.z());
  }

 private:
  std::int64_t& at(int x, int y, int z) {
    const std::size_t side = static_cast<std::size_t>(r_) + 1;
    return sum_[(static_cast<std::size_t>(z) * side + y) * side + x];
  }
  std::int64_t at(int x, int y, int z) const { return const_cast<CellCounts*>(this)->at(x, y, z); }

  int r_;
  std::vector<std::int64_t> sum_;
};

void split(const CellCounts& counts, const CellBox& box, std::int64_t limit,
           std::vector<CellBox>& out) {
  const std::int64_t n = counts.count(box);
  const Eigen::Vector3i size = box.end - box.first;
  if (n == 0) return;  // empty boxes make no tiles (their cells stay unowned: no point is there)
  if (n <= limit || size.maxCoeff() == 1) {
    out.push_back(box);
    return;
  }
  // Halve along the longest side (in cells) at the boundary nearest the median point.
  int axis = 0;
  size.maxCoeff(&axis);
  int best_cut = box.first[axis] + 1;
  std::int64_t best_gap = -1;
  for (int cut = box.first[axis] + 1; cut < box.end[axis]; ++cut) {
    CellBox low = box;
    low.end[axis] = cut;
    const std::int64_t gap = std::abs(2 * counts.count(low) - n);
    if (best_gap < 0 || gap < best_gap) {
      best_gap = gap;
      best_cut = cut;
    }
  }
  CellBox low = box, high = box;
  low.end[axis] = best_cut;
  high.first[axis] = best_cut;
  split(counts, low, limit, out);
  split(counts, high, limit, out);
}

}  // namespace

TilePlan planTiles(const PointHistogram& histogram, std::int64_t max_points_per_tile) {
  if (max_points_per_tile < 1) throw pcl::BadArgumentException("a tile must hold a point");
  const int r = histogram.resolution();
  const CellCounts counts(histogram);
  std::vector<CellBox> boxes;
  split(counts, {Eigen::Vector3i::Zero(), Eigen::Vector3i::Constant(r)}, max_points_per_tile,
        boxes);

  TilePlan plan{histogram, {}, std::vector<int>(histogram.counts().size(), -1)};
  const Eigen::Vector3d cell_size = histogram.bounds().sizes() / r;
  for (const CellBox& b : boxes) {
    Tile tile;
    tile.first_cell = b.first;
    tile.end_cell = b.end;
    tile.box = Eigen::AlignedBox3d(
        histogram.bounds().min() + cell_size.cwiseProduct(b.first.cast<double>()),
        histogram.bounds().min() + cell_size.cwiseProduct(b.end.cast<double>()));
    tile.points = counts.count(b);
    const int id = static_cast<int>(plan.tiles.size());
    for (int z = b.first.z(); z < b.end.z(); ++z)
      for (int y = b.first.y(); y < b.end.y(); ++y)
        for (int x = b.first.x(); x < b.end.x(); ++x)
          plan.tile_of_cell[(static_cast<std::size_t>(z) * r + y) * r + x] = id;
    plan.tiles.push_back(tile);
  }
  return plan;
}

std::string TilePlan::toJson() const {
  std::ostringstream out;
  out.precision(17);
  const auto vec = [&](const auto& v) {
    out << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
  };
  out << "{\"bounds\": {\"min\": ";
  vec(histogram.bounds().min());
  out << ", \"max\": ";
  vec(histogram.bounds().max());
  out << "}, \"resolution\": " << histogram.resolution() << ", \"tiles\": [";
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    out << (t ? ", " : "") << "{\"id\": " << t << ", \"first_cell\": ";
    vec(tiles[t].first_cell);
    out << ", \"end_cell\": ";
    vec(tiles[t].end_cell);
    out << ", \"min\": ";
    vec(tiles[t].box.min());
    out << ", \"max\": ";
    vec(tiles[t].box.max());
    out << ", \"points\": " << tiles[t].points << "}";
  }
  out << "]}";
  return out.str();
}

}  // namespace pcl_ddg
