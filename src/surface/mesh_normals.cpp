#include "pcl_ddg/surface/mesh_normals.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <limits>

#include "../operators/triangle_geometry.h"
#include "pcl_ddg/mesh/mesh_geometry.h"

namespace pcl_ddg {

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

  const int n = topology.numVertices();
  MeshNormals result;
  result.normals.resize(3, n);
  result.valid.assign(n, 0);
  std::int64_t invalid = 0, fallback = 0;
#pragma omp parallel for schedule(static) reduction(+ : invalid, fallback)
  for (int v = 0; v < n; ++v) {
    Eigen::Vector3d area_sum = Eigen::Vector3d::Zero(), sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d laplace = Eigen::Vector3d::Zero();
    double mass = 0.0;
    detail::forEachCornerOf(topology, positions, v, [&](const detail::CornerView& c, int) {
      area_sum += c.area_vector;
      switch (weighting) {
        case NormalWeighting::Uniform: sum += c.area_vector / c.area_vector.norm(); break;
        case NormalWeighting::Angle: sum += c.angle() * c.area_vector / c.area_vector.norm(); break;
        case NormalWeighting::MeanCurvature:
          laplace += detail::cotangentLaplacianPart(c);
          mass += detail::cornerMass(c, options.mass);
          break;
        case NormalWeighting::Area: break;
      }
    });
    if (weighting == NormalWeighting::Area) sum = area_sum;
    if (weighting == NormalWeighting::MeanCurvature) {
      // -M^-1 L x; on the boundary it also holds the boundary curve's curvature (in the plane).
      const Eigen::Vector3d towards_normal = mass > 0.0 ? Eigen::Vector3d(-laplace / mass)
                                                        : Eigen::Vector3d::Zero();
      const double magnitude = towards_normal.norm();
      if (!topology.isBoundary(v) && magnitude >= epsilon && magnitude > 0.0) {
        sum = towards_normal.dot(area_sum) < 0.0 ? Eigen::Vector3d(-towards_normal) : towards_normal;
      } else {
        sum = area_sum;
        if (area_sum.squaredNorm() > 0.0) ++fallback;
      }
    }
    const double length = sum.norm();
    if (length > 0.0 && std::isfinite(length)) {
      result.normals.col(v) = sum / length;
      result.valid[v] = 1;
    } else {
      result.normals.col(v).setConstant(std::numeric_limits<double>::quiet_NaN());
      ++invalid;
    }
  }
  result.invalid_vertices = invalid;
  result.fallback_vertices = fallback;
  return result;
}

}  // namespace pcl_ddg
