#include "pcl_ddg/mesh/mesh_geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace pcl_ddg {

double meanEdgeLength(const MeshTopology& topology, const PositionsRef& positions) {
  // Each edge once, from its smaller end, in the order of edge ids (smaller, then larger vertex),
  // read from the neighbour rows: the edge map is not needed. Summed in fixed blocks of that order,
  // then the block sums in order: parallel, and the same last bit whatever the thread count.
  constexpr std::int64_t kBlock = 1 << 16;
  const int n = topology.numVertices();
  std::vector<std::int64_t> first_edge(static_cast<std::size_t>(n) + 1, 0);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < n; ++v) {
    const IndexSpan row = topology.neighbours(v);
    first_edge[v + 1] = row.end() - std::upper_bound(row.begin(), row.end(), v);
  }
  std::partial_sum(first_edge.begin(), first_edge.end(), first_edge.begin());
  const std::int64_t edges = first_edge.back();
  const std::int64_t blocks = (edges + kBlock - 1) / kBlock;
  std::vector<double> block_sum(static_cast<std::size_t>(blocks), 0.0);
  std::int64_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
  for (std::int64_t b = 0; b < blocks; ++b) {
    std::int64_t e = b * kBlock;
    const std::int64_t end = std::min(edges, e + kBlock);
    double sum = 0.0;
    // The vertex whose larger neighbours hold edge e, then on along the rows.
    int v = static_cast<int>(std::upper_bound(first_edge.begin(), first_edge.end(), e) -
                             first_edge.begin() - 1);
    for (; e < end; ++v) {
      const IndexSpan row = topology.neighbours(v);
      const int smaller = row.size() - static_cast<int>(first_edge[v + 1] - first_edge[v]);
      for (int i = smaller + static_cast<int>(e - first_edge[v]); i < row.size() && e < end;
           ++i, ++e) {
        const double length = (positions.col(v) - positions.col(row[i])).norm();
        if (!std::isfinite(length)) continue;
        sum += length;
        ++count;
      }
    }
    block_sum[static_cast<std::size_t>(b)] = sum;
  }
  double sum = 0.0;
  for (const double s : block_sum) sum += s;
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

TriangleQuality triangleQuality(const MeshTopology& topology, const PositionsRef& positions) {
  constexpr double kDegreesPerRadian = 57.295779513082320876798;
  const Eigen::Matrix3Xi& t = topology.triangles();
  const std::int64_t triangles = t.cols();
  double min_angle = 180.0;
  std::int64_t slivers = 0;
#pragma omp parallel for schedule(static) reduction(min : min_angle) reduction(+ : slivers)
  for (std::int64_t f = 0; f < triangles; ++f) {
    const Eigen::Vector3d p[3] = {positions.col(t(0, f)), positions.col(t(1, f)),
                                  positions.col(t(2, f))};
    if (isDegenerateTriangle(p[0], p[1], p[2])) continue;
    // The smallest angle is opposite the shortest side (law of sines): one atan2, not three.
    const double opposite[3] = {(p[2] - p[1]).squaredNorm(), (p[0] - p[2]).squaredNorm(),
                                (p[1] - p[0]).squaredNorm()};
    const int k = static_cast<int>(std::min_element(opposite, opposite + 3) - opposite);
    const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
    const double smallest = kDegreesPerRadian * std::atan2(u.cross(v).norm(), u.dot(v));
    min_angle = std::min(min_angle, smallest);
    slivers += smallest < kSliverAngleDegrees;
  }
  TriangleQuality quality;
  quality.min_angle_degrees = min_angle;
  quality.slivers = slivers;
  return quality;
}

BoundingBox boundingBox(const PositionsRef& positions) {
  BoundingBox box;
  bool any = false;
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    if (!positions.col(i).allFinite()) continue;
    if (!any) {
      box.min = box.max = positions.col(i);
      any = true;
    }
    box.min = box.min.cwiseMin(positions.col(i));
    box.max = box.max.cwiseMax(positions.col(i));
  }
  return box;
}

}  // namespace pcl_ddg
