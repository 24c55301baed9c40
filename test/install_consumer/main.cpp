// A program outside the project that uses the installed package.
#include <pcl_ddg/mesh/mesh_report.h>
#include <pcl_ddg/mesh/mesh_topology.h>
#include <pcl_ddg/version.h>

#include <iostream>

int main() {
  Eigen::Matrix3Xi triangles(3, 4);
  triangles << 0, 0, 0, 1, 1, 2, 3, 3, 2, 3, 1, 2;  // a tetrahedron, outward winding
  Eigen::Matrix3Xd points(3, 4);
  points << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  const pcl_ddg::MeshTopology topology(4, triangles);
  const pcl_ddg::MeshReport report = pcl_ddg::makeMeshReport(topology, points);
  std::cout << "pcl_ddg " << PCL_DDG_VERSION_STRING << ": " << report.toJson() << "\n";
  return report.euler_characteristic == 2 ? 0 : 1;
}
