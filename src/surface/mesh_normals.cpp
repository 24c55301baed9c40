#include "pcl_ddg/surface/mesh_normals.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <limits>

#include "../operators/triangle_geometry.h"
#include "pcl_ddg/mesh/mesh_geometry.h"

namespace pcl_ddg {
namespace {

// Uniform and area weightings: each triangle's normal once (parallel over triangles), then
// gathered per vertex. Returns unnormalised directions.
Eigen::Matrix3Xd faceNormalSums(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                                NormalWeighting weighting) {
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  Eigen::Matrix3Xd face_normal(3, triangles.cols());
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    const detail::CornerView c =
        detail::viewFromCorner(positions, triangles, static_cast<int>(t), 0);
    if (c.degenerate) {
      face_normal.col(t).setZero();
    } else {
      face_normal.col(t) = weighting == NormalWeighting::Area
                               ? c.area_vector
                               : Eigen::Vector3d(2.0 * c.area_vector / c.double_area);
    }
  }
  Eigen::Matrix3Xd sums(3, topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int t : topology.incidentTriangles(v)) sum += face_normal.col(t);
    sums.col(v) = sum;
  }
  return sums;
}

// Angle weighting: every corner has its own weight, so each vertex gathers its triangles whole
// (a per-triangle array of angles measured slower: its fresh pages cost more than the flops).
Eigen::Matrix3Xd angleWeightedSums(const MeshTopology& topology,
                                   const Eigen::Matrix3Xd& positions) {
  Eigen::Matrix3Xd sums(3, topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    detail::forEachCornerOf(topology, positions, v, [&](const detail::CornerView& c, int) {
      sum += c.angle() * 2.0 * c.area_vector / c.double_area;
    });
    sums.col(v) = sum;
  }
  return sums;
}

// -M^-1 L x turned towards the area normal, or the area normal where it is shorter than epsilon
// or on the boundary (counted in fallback).
Eigen::Matrix3Xd meanCurvatureDirections(const MeshTopology& topology,
                                         const Eigen::Matrix3Xd& positions, MassType mass_type,
                                         double epsilon, std::int64_t& fallback) {
  Eigen::Matrix3Xd directions(3, topology.numVertices());
  std::int64_t fallback_count = 0;
#pragma omp parallel for schedule(static) reduction(+ : fallback_count)
  for (int v = 0; v < topology.numVertices(); ++v) {
    Eigen::Vector3d area_normal = Eigen::Vector3d::Zero(), laplace = Eigen::Vector3d::Zero();
    double mass = 0.0;
    detail::forEachCornerOf(topology, positions, v, [&](const detail::CornerView& c, int) {
      area_normal += c.area_vector;
      laplace += detail::cotangentLaplacianPart(c);
      mass += detail::cornerMass(c, mass_type);
    });
    const Eigen::Vector3d towards_normal =
        mass > 0.0 ? Eigen::Vector3d(-laplace / mass) : Eigen::Vector3d::Zero();
    const double magnitude = towards_normal.norm();
    if (!topology.isBoundary(v) && magnitude >= epsilon && magnitude > 0.0) {
      directions.col(v) =
          towards_normal.dot(area_normal) < 0.0 ? Eigen::Vector3d(-towards_normal) : towards_normal;
    } else {
      directions.col(v) = area_normal;
      if (area_normal.squaredNorm() > 0.0) ++fallback_count;
    }
  }
  fallback = fallback_count;
  return directions;
}

}  // namespace

MeshNormals computeMeshNormals(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
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
  switch (weighting) {
    case NormalWeighting::Uniform:
    case NormalWeighting::Area:
      result.normals = faceNormalSums(topology, positions, weighting);
      break;
    case NormalWeighting::Angle:
      result.normals = angleWeightedSums(topology, positions);
      break;
    case NormalWeighting::MeanCurvature:
      result.normals = meanCurvatureDirections(topology, positions, options.mass, epsilon,
                                               result.fallback_vertices);
      break;
  }
  const int n = topology.numVertices();
  result.valid.assign(n, 0);
  std::int64_t invalid = 0;
#pragma omp parallel for schedule(static) reduction(+ : invalid)
  for (int v = 0; v < n; ++v) {
    const double length = result.normals.col(v).norm();
    if (length > 0.0 && std::isfinite(length)) {
      result.normals.col(v) /= length;
      result.valid[v] = 1;
    } else {
      result.normals.col(v).setConstant(std::numeric_limits<double>::quiet_NaN());
      ++invalid;
    }
  }
  result.invalid_vertices = invalid;
  return result;
}

}  // namespace pcl_ddg
