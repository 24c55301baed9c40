#include "pcl_ddg/features/normal_orientation.h"

#include <Eigen/Geometry>

namespace pcl_ddg {

Eigen::Matrix3Xd meshOrientationNormals(const MeshTopology& topology,
                                        const Eigen::Matrix3Xd& positions) {
  const Eigen::Matrix3Xi& triangles = topology.triangles();
  Eigen::Matrix3Xd normals(3, topology.numVertices());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < topology.numVertices(); ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int t : topology.incidentTriangles(v)) {
      const Eigen::Vector3d a = positions.col(triangles(0, t));
      const Eigen::Vector3d area =
          (positions.col(triangles(1, t)) - a).cross(positions.col(triangles(2, t)) - a);
      if (area.allFinite()) sum += area;
    }
    normals.col(v) = sum;
  }
  return normals;
}

}  // namespace pcl_ddg
