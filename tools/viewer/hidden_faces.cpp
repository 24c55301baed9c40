#include "viewer/hidden_faces.h"

#include <vtkCamera.h>

#include <vector>

namespace pcl_ddg {
namespace viewer {

bool facesOutward(const MeshTopology& topology, const Eigen::Matrix3Xd& positions) {
  const TopologyCounts& counts = topology.counts();
  if (topology.numTriangles() == 0 || counts.boundary_edges != 0 || counts.nonmanifold_edges != 0 ||
      !counts.consistently_oriented || !positions.allFinite()) {
    return false;
  }
  // Six times each component's volume, from tetrahedra to a point near the surface (a closed
  // component's volume does not depend on that point; scans far from the origin lose no digits).
  const Eigen::Vector3d origin = positions.rowwise().mean();
  const Eigen::Matrix3Xi& t = topology.triangles();
  const std::vector<int>& component = topology.vertexComponent();
  std::vector<double> six_volume(counts.connected_components, 0.0);
  for (Eigen::Index f = 0; f < t.cols(); ++f) {
    const Eigen::Vector3d a = positions.col(t(0, f)) - origin, b = positions.col(t(1, f)) - origin,
                          c = positions.col(t(2, f)) - origin;
    six_volume[component[t(0, f)]] += a.dot(b.cross(c));
  }
  for (double v : six_volume) {
    if (!(v > 0.0)) return false;
  }
  return true;
}

bool boxBeyondNearPlane(vtkCamera& camera, const double bounds[6]) {
  double position[3], direction[3], near_far[2];
  camera.GetPosition(position);
  camera.GetDirectionOfProjection(direction);
  camera.GetClippingRange(near_far);
  for (int corner = 0; corner < 8; ++corner) {
    double depth = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      const double coordinate = bounds[2 * axis + ((corner >> axis) & 1)];
      depth += (coordinate - position[axis]) * direction[axis];
    }
    if (!(depth >= near_far[0])) return false;
  }
  return true;
}

}  // namespace viewer
}  // namespace pcl_ddg
