#include "pcl_ddg/surface/mesh_normals.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <limits>

#include "detail/triangle_geometry.h"
#include "detail/vertex_ranges.h"
#include "pcl_ddg/mesh/mesh_geometry.h"

namespace pcl_ddg {
namespace {

// Per vertex, the weighted sum of the face normals and the sum of the weighted normals' lengths
// (which tells a sum that cancelled from a short one).
struct NormalSums {
  Eigen::Matrix3Xd sums;
  Eigen::VectorXd lengths;
};

// Uniform and area weightings: each thread adds the normals of the triangles with a corner in its
// own range of vertices to those corners (a triangle across two ranges is computed by both). Each
// vertex sums its triangles in ascending order whatever the number of threads, and no per-triangle
// array is needed: it was 48 B a vertex at the peak of a tool's run, and with its pages fresh, as
// in a tool's run, the normals took twice as long.
NormalSums faceNormalSums(const MeshTopology& topology, const PositionsRef& positions,
                          NormalWeighting weighting) {
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  const int n = topology.numVertices();
  NormalSums result{Eigen::Matrix3Xd(3, n), Eigen::VectorXd(n)};
  detail::forEachVertexRange(n, [&](int first, int last) {
    result.sums.middleCols(first, last - first).setZero();
    result.lengths.segment(first, last - first).setZero();
    const auto mine = [&](int v) { return v >= first && v < last; };
    for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
      const bool own[3] = {mine(triangles(0, t)), mine(triangles(1, t)), mine(triangles(2, t))};
      if (!(own[0] || own[1] || own[2])) continue;
      const Eigen::Vector3d& a = positions.col(triangles(0, t));
      const Eigen::Vector3d& b = positions.col(triangles(1, t));
      const Eigen::Vector3d& d = positions.col(triangles(2, t));
      const Eigen::Vector3d cross = (b - a).cross(d - a);
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      double length = 0.0;
      if (!isDegenerateTriangle(a, b, d, cross)) {
        normal = 0.5 * cross;  // the area vector
        length = normal.norm();
        if (weighting == NormalWeighting::Uniform) {
          normal /= length;
          length = normal.norm();
        }
      }
      for (int k = 0; k < 3; ++k) {
        if (!own[k]) continue;
        result.sums.col(triangles(k, t)) += normal;
        result.lengths[triangles(k, t)] += length;
      }
    }
  });
  return result;
}

// Angle weighting: every corner has its own weight, so each vertex gathers its triangles whole
// (a per-triangle array of angles measured slower: its fresh pages cost more than the flops).
NormalSums angleWeightedSums(const MeshTopology& topology, const PositionsRef& positions) {
  NormalSums result{Eigen::Matrix3Xd(3, topology.numVertices()),
                    Eigen::VectorXd(topology.numVertices())};
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double length = 0.0;
    detail::forEachCornerOf(topology, positions, v, [&](const detail::CornerView& c, int) {
      const double angle = c.angle();
      sum += angle * 2.0 * c.area_vector / c.double_area;
      length += angle;
    });
    result.sums.col(v) = sum;
    result.lengths[v] = length;
  }
  return result;
}

// -M^-1 L x turned towards the area normal, or the area normal where it is shorter than epsilon
// or on the boundary (counted in fallback). Where the area normal has cancelled, the turn is
// undecided: that vertex gets the (cancelled) area sum, which becomes NaN.
NormalSums meanCurvatureDirections(const MeshTopology& topology, const PositionsRef& positions,
                                   MassType mass_type, double epsilon, std::int64_t& fallback) {
  NormalSums result{Eigen::Matrix3Xd(3, topology.numVertices()),
                    Eigen::VectorXd(topology.numVertices())};
  std::int64_t fallback_count = 0;
#pragma omp parallel for schedule(static) reduction(+ : fallback_count)
  for (int v = 0; v < topology.numVertices(); ++v) {
    const detail::VertexSums s = detail::gatherVertexSums<false>(topology, positions, v, mass_type);
    const Eigen::Vector3d& area_normal = s.area_normal;
    const Eigen::Vector3d towards_normal =
        s.mass > 0.0 ? Eigen::Vector3d(-s.laplace / s.mass) : Eigen::Vector3d::Zero();
    const double magnitude = towards_normal.norm();
    result.lengths[v] = s.area;
    if (detail::hasCancelled(area_normal, s.area)) {
      result.sums.col(v) = area_normal;
    } else if (!topology.isBoundary(v) && magnitude >= epsilon && magnitude > 0.0) {
      result.sums.col(v) =
          towards_normal.dot(area_normal) < 0.0 ? Eigen::Vector3d(-towards_normal) : towards_normal;
      result.lengths[v] = 0.0;  // -M^-1 L x is not a sum of normals: no cancellation test
    } else {
      result.sums.col(v) = area_normal;
      ++fallback_count;
    }
  }
  fallback = fallback_count;
  return result;
}

}  // namespace

MeshNormals computeMeshNormals(const MeshTopology& topology, const PositionsRef& positions,
                               const MeshNormalOptions& options) {
  detail::requireMatchingPositions(topology, positions);
  const NormalWeighting weighting = options.weighting;
  double epsilon = options.epsilon;
  if (weighting != NormalWeighting::MeanCurvature && epsilon >= 0.0) {
    throw pcl::BadArgumentException("epsilon applies to mean-curvature normals only");
  }
  if (weighting == NormalWeighting::MeanCurvature && epsilon < 0.0) {
    const double h = meanEdgeLength(topology, positions);
    epsilon = h > 0.0 ? 0.02 / h : 0.0;
  }

  MeshNormals result;
  NormalSums sums;
  switch (weighting) {
    case NormalWeighting::Uniform:
    case NormalWeighting::Area:
      sums = faceNormalSums(topology, positions, weighting);
      break;
    case NormalWeighting::Angle:
      sums = angleWeightedSums(topology, positions);
      break;
    case NormalWeighting::MeanCurvature:
      sums = meanCurvatureDirections(topology, positions, options.mass, epsilon,
                                     result.fallback_vertices);
      break;
  }
  const int n = topology.numVertices();
  result.normals.swap(sums.sums);
  result.valid.assign(n, 0);
  std::int64_t invalid = 0, cancelled = 0;
#pragma omp parallel for schedule(static) reduction(+ : invalid, cancelled)
  for (int v = 0; v < n; ++v) {
    const double length = result.normals.col(v).norm();
    const bool has_cancelled =
        sums.lengths[v] > 0.0 && detail::hasCancelled(result.normals.col(v), sums.lengths[v]);
    if (length > 0.0 && std::isfinite(length) && !has_cancelled) {
      result.normals.col(v) /= length;
      result.valid[v] = 1;
    } else {
      result.normals.col(v).setConstant(std::numeric_limits<double>::quiet_NaN());
      ++invalid;
      cancelled += has_cancelled;
    }
  }
  result.invalid_vertices = invalid;
  result.cancelled_vertices = cancelled;
  return result;
}

}  // namespace pcl_ddg
