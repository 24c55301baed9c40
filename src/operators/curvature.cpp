#include "pcl_ddg/operators/curvature.h"

#include <cmath>
#include <limits>

#include "detail/triangle_geometry.h"

namespace pcl_ddg {
Eigen::VectorXd angleDefect(const MeshTopology& topology, const PositionsRef& positions) {
  detail::requireMatchingPositions(topology, positions);
  Eigen::VectorXd defect(topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    if (topology.isIsolated(v)) {
      defect[v] = 0.0;
      continue;
    }
    double angle_sum = 0.0;
    detail::forEachCornerOf(topology, positions, v,
                            [&](const detail::CornerView& c, int) { angle_sum += c.angle(); });
    defect[v] = detail::angleDefectAt(topology.isBoundary(v), angle_sum);
  }
  return defect;
}

Eigen::Matrix3Xd meanCurvatureNormal(const MeshTopology& topology, const PositionsRef& positions,
                                     MassType mass) {
  detail::requireMatchingPositions(topology, positions);
  Eigen::Matrix3Xd hn(3, topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    const detail::VertexSums s = detail::gatherVertexSums<false>(topology, positions, v, mass);
    hn.col(v) = s.mass > 0.0 ? Eigen::Vector3d(-0.5 * s.laplace / s.mass) : Eigen::Vector3d::Zero();
  }
  return hn;
}

VertexCurvatures computeCurvatures(const MeshTopology& topology, const PositionsRef& positions,
                                   MassType mass) {
  detail::requireMatchingPositions(topology, positions);
  const int n = topology.numVertices();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  VertexCurvatures c;
  c.vertex_area.resize(n);
  c.mean_curvature.resize(n);
  c.gauss_curvature.resize(n);
  c.k1.resize(n);
  c.k2.resize(n);
  c.valid.assign(n, 0);
  std::int64_t clamped = 0, invalid = 0, unoriented = 0;
#pragma omp parallel for schedule(static) reduction(+ : clamped, invalid, unoriented)
  for (int v = 0; v < n; ++v) {
    const detail::VertexSums s = detail::gatherVertexSums<true>(topology, positions, v, mass);
    c.vertex_area[v] = s.mass;
    if (!(s.mass > 0.0)) {
      c.mean_curvature[v] = c.gauss_curvature[v] = c.k1[v] = c.k2[v] = nan;
      ++invalid;
      continue;
    }
    c.gauss_curvature[v] = detail::angleDefectAt(topology.isBoundary(v), s.angle_sum) / s.mass;
    if (detail::hasCancelled(s.area_normal, s.area)) {
      // No orientation to sign H by: only K, which needs none, is given.
      c.mean_curvature[v] = c.k1[v] = c.k2[v] = nan;
      ++invalid;
      ++unoriented;
      continue;
    }
    c.valid[v] = 1;
    const Eigen::Vector3d hn = -0.5 * s.laplace / s.mass;
    c.mean_curvature[v] = hn.dot(s.area_normal) < 0.0 ? -hn.norm() : hn.norm();
    const double discriminant = c.mean_curvature[v] * c.mean_curvature[v] - c.gauss_curvature[v];
    if (discriminant < 0.0) ++clamped;
    const double root = std::sqrt(std::max(discriminant, 0.0));
    c.k1[v] = c.mean_curvature[v] + root;
    c.k2[v] = c.mean_curvature[v] - root;
  }
  c.clamped_vertices = clamped;
  c.invalid_vertices = invalid;
  c.unoriented_vertices = unoriented;
  return c;
}

}  // namespace pcl_ddg
