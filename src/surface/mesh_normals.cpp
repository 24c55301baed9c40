#include "pcl_ddg/surface/mesh_normals.h"

#include <pcl/exceptions.h>

#include <cmath>
#include <limits>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/operators/laplacian.h"
#include "pcl_ddg/operators/triangle_quantities.h"

namespace pcl_ddg {

MeshNormals computeMeshNormals(const MeshTopology& topology, const Eigen::Matrix3Xd& positions,
                               const MeshNormalOptions& options) {
  const TriangleQuantities q = computeTriangleQuantities(topology, positions);
  const Eigen::Matrix3Xi& tris = topology.triangles();
  const int n = topology.numVertices();

  Eigen::Matrix3Xd laplace;  // M^-1 L x, only for the mean-curvature weighting
  double epsilon = options.epsilon;
  if (options.weighting == NormalWeighting::MeanCurvature) {
    Eigen::SparseMatrix<double> l = cotangentLaplacian(topology, q);
    divideRowsByMass(l, lumpedMass(topology, positions, q, options.mass));
    laplace = (l * positions.transpose()).transpose();
    if (epsilon < 0.0) {
      const double h = meanEdgeLength(topology, positions);
      epsilon = h > 0.0 ? 0.02 / h : 0.0;
    }
  } else if (options.epsilon >= 0.0) {
    throw pcl::BadArgumentException("epsilon applies to mean-curvature normals only");
  }

  MeshNormals result;
  result.normals.resize(3, n);
  result.valid.assign(n, 0);
  std::int64_t invalid = 0, fallback = 0;
#pragma omp parallel for schedule(static) reduction(+ : invalid, fallback)
  for (int v = 0; v < n; ++v) {
    Eigen::Vector3d area_sum = Eigen::Vector3d::Zero(), sum = Eigen::Vector3d::Zero();
    for (const int t : topology.incidentTriangles(v)) {
      const double area = q.areas[t];
      if (area == 0.0) continue;
      const Eigen::Vector3d unit = q.area_vectors.col(t) / area;
      area_sum += q.area_vectors.col(t);
      if (options.weighting == NormalWeighting::Uniform) sum += unit;
      if (options.weighting == NormalWeighting::Angle) {
        const int k = tris(0, t) == v ? 0 : (tris(1, t) == v ? 1 : 2);
        sum += q.angles(k, t) * unit;
      }
    }
    if (options.weighting == NormalWeighting::Area) sum = area_sum;
    if (options.weighting == NormalWeighting::MeanCurvature) {
      const Eigen::Vector3d towards_normal = -laplace.col(v);
      const double magnitude = towards_normal.norm();
      // On the boundary -L x also holds the boundary's own curvature (in the tangent plane).
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
