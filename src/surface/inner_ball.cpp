#include "pcl_ddg/surface/inner_ball.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pcl_ddg/search/point_kd_tree.h"
#include "pcl_ddg/surface/mesh_normals.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {

Eigen::VectorXd innerBallRadii(const MeshTopology& topology, const PositionsRef& positions,
                               double largest) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const int n = topology.numVertices();
  Eigen::VectorXd radii = Eigen::VectorXd::Constant(n, kInfinity);
  if (n == 0 || topology.numTriangles() == 0) return radii;

  std::vector<int> used;
  for (int v = 0; v < n; ++v) {
    if (!topology.isIsolated(v)) used.push_back(v);
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const int v : used) centre += positions.col(v);
  centre /= static_cast<double>(used.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInfinity), hi = -lo;
  std::vector<float> xyz;
  xyz.reserve(3 * used.size());
  for (const int v : used) {
    const Eigen::Vector3d p = positions.col(v) - centre;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    for (int d = 0; d < 3; ++d) xyz.push_back(static_cast<float>(p[d]));
  }
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0.0)) return radii;
  const detail::PointKdTree tree(std::move(xyz), pcl::Indices(used.begin(), used.end()));

  const MeshNormals normals = computeMeshNormals(topology, positions);
  // Outward: the faces' side, turned over on each closed component that encloses a negative
  // volume (faces wound inward).
  const std::vector<int>& component = topology.vertexComponent();
  const std::vector<double> volumes = componentVolumes(topology, positions);
  const int components = static_cast<int>(volumes.size());
  std::vector<char> open(components, 0);
  for (const int v : used) open[component[v]] |= topology.isBoundary(v);
  const bool oriented =
      topology.counts().consistently_oriented && topology.counts().nonmanifold_edges == 0;
  std::vector<double> outward(components, 1.0);
  for (int k = 0; k < components; ++k) {
    if (oriented && !open[k] && volumes[k] < 0.0) outward[k] = -1.0;
  }

  const int count = static_cast<int>(used.size());
#pragma omp parallel
  {
    pcl::Indices nearest;
    std::vector<float> squared;
#pragma omp for schedule(dynamic, 256)
    for (int i = 0; i < count; ++i) {
      const int v = used[i];
      if (!normals.valid[v]) continue;
      const Eigen::Vector3d p = positions.col(v) - centre;
      const Eigen::Vector3d normal = outward[component[v]] * normals.normals.col(v);
      double r = largest < diagonal ? largest : diagonal;
      // Each pass shrinks r strictly; 64 passes are far more than a surface needs (usually under
      // 10). Were they spent, r would be an upper bound.
      for (int pass = 0; pass < 64; ++pass) {
        const Eigen::Vector3f c = (p - r * normal).cast<float>();
        if (tree.nearestK(c.data(), 1, nearest, squared) < 1 || nearest[0] == v) break;
        const Eigen::Vector3d pq = p - (positions.col(nearest[0]) - centre);
        // |c - q| with c = p - r n and q = p - pq: q on the sphere (p's exact doubles) or outside,
        // the ball is empty.
        if ((pq - r * normal).norm() >= r * (1.0 - 1e-9)) break;
        const double along = 2.0 * normal.dot(pq);
        const double shrunk = along > 0.0 ? pq.squaredNorm() / along : r;
        if (!(shrunk < r)) break;
        r = shrunk;
      }
      if (r < diagonal) radii[v] = r;  // a ball as wide as the surface: nothing constrains it
    }
  }
  return radii;
}

}  // namespace pcl_ddg
