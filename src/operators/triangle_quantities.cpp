#include "pcl_ddg/operators/triangle_quantities.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {

void requireMatchingPositions(const MeshTopology& topology, const Eigen::Matrix3Xd& positions) {
  if (positions.cols() != topology.numVertices()) {
    throw InvalidMeshException("positions have " + std::to_string(positions.cols()) +
                               " columns for a mesh of " + std::to_string(topology.numVertices()) +
                               " vertices");
  }
  requireFinite(positions);
}

TriangleQuantities computeTriangleQuantities(const MeshTopology& topology,
                                             const Eigen::Matrix3Xd& positions) {
  requireMatchingPositions(topology, positions);
  const Eigen::Matrix3Xi& tris = topology.triangles();
  const Eigen::Index num_triangles = tris.cols();
  TriangleQuantities q;
  q.areas.setZero(num_triangles);
  q.area_vectors.setZero(3, num_triangles);
  q.angles.setZero(3, num_triangles);
  q.cotangents.setZero(3, num_triangles);
  std::int64_t degenerate = 0;
#pragma omp parallel for schedule(static) reduction(+ : degenerate)
  for (Eigen::Index t = 0; t < num_triangles; ++t) {
    const Eigen::Vector3d p[3] = {positions.col(tris(0, t)), positions.col(tris(1, t)),
                                  positions.col(tris(2, t))};
    if (isDegenerateTriangle(p[0], p[1], p[2])) {
      ++degenerate;
      continue;
    }
    const Eigen::Vector3d area_vector = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]);
    const double double_area = 2.0 * area_vector.norm();
    q.area_vectors.col(t) = area_vector;
    q.areas[t] = 0.5 * double_area;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
      const double dot = u.dot(v);
      // |u x v| is twice the area at every corner; atan2 stays accurate for tiny and obtuse angles.
      q.angles(k, t) = std::atan2(double_area, dot);
      q.cotangents(k, t) = dot / double_area;
    }
  }
  q.degenerate_triangles = degenerate;
  return q;
}

}  // namespace pcl_ddg
