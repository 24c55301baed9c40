#include "pcl_ddg/mesh/mesh_geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace pcl_ddg {

double meanEdgeLength(const MeshTopology& topology, const Eigen::Matrix3Xd& positions) {
  const Eigen::Matrix2Xi& edges = topology.edgeVertices();
  double sum = 0.0;
  Eigen::Index count = 0;
  for (Eigen::Index e = 0; e < edges.cols(); ++e) {
    const double length = (positions.col(edges(0, e)) - positions.col(edges(1, e))).norm();
    if (!std::isfinite(length)) continue;
    sum += length;
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
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
