#include "pcl_ddg/mesh/mesh_geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

namespace pcl_ddg {

double meanEdgeLength(const MeshTopology& topology, const Eigen::Matrix3Xd& positions) {
  // Summed in fixed blocks, then the block sums in order: parallel, and the same last bit
  // whatever the thread count.
  constexpr Eigen::Index kBlock = 1 << 16;
  const Eigen::Matrix2Xi& edges = topology.edgeVertices();
  const Eigen::Index blocks = (edges.cols() + kBlock - 1) / kBlock;
  std::vector<double> block_sum(static_cast<std::size_t>(blocks), 0.0);
  Eigen::Index count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
  for (Eigen::Index b = 0; b < blocks; ++b) {
    double sum = 0.0;
    for (Eigen::Index e = b * kBlock; e < std::min(edges.cols(), (b + 1) * kBlock); ++e) {
      const double length = (positions.col(edges(0, e)) - positions.col(edges(1, e))).norm();
      if (!std::isfinite(length)) continue;
      sum += length;
      ++count;
    }
    block_sum[static_cast<std::size_t>(b)] = sum;
  }
  double sum = 0.0;
  for (const double s : block_sum) sum += s;
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

TriangleQuality triangleQuality(const MeshTopology& topology, const Eigen::Matrix3Xd& positions) {
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

BoundingBox boundingBox(const Eigen::Matrix3Xd& positions) {
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
