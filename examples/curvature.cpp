// Discrete curvatures of a mesh: mean H (cotangent Laplacian), Gaussian K (angle defect) and the
// principal curvatures, per vertex, with the Gauss-Bonnet check sum(K * area) = 2 pi chi on a
// closed mesh.
//   example_curvature mesh.ply
#include <cmath>
#include <iostream>

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/operators/curvature.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " mesh.{ply,obj,off,stl,vtk}\n";
    return 2;
  }
  const pcl::PolygonMesh mesh = pcl_ddg::loadMesh(argv[1]);
  const pcl_ddg::MeshTopology topology(mesh);
  const Eigen::Matrix3Xd positions = pcl_ddg::vertexPositions(mesh.cloud);
  const pcl_ddg::VertexCurvatures c = pcl_ddg::computeCurvatures(topology, positions);

  double total_gauss = 0.0;
  for (Eigen::Index v = 0; v < c.gauss_curvature.size(); ++v) {
    if (c.valid[v]) total_gauss += c.gauss_curvature[v] * c.vertex_area[v];
  }
  const double two_pi_chi = 2.0 * 3.14159265358979323846 * topology.eulerCharacteristic();
  std::cout << "vertex 0: H = " << c.mean_curvature[0] << ", K = " << c.gauss_curvature[0]
            << ", k1 = " << c.k1[0] << ", k2 = " << c.k2[0] << "\n"
            << "sum K dA = " << total_gauss
            << ", 2 pi chi = " << 2.0 * 3.14159265358979 * topology.eulerCharacteristic() << "\n";
  return 0;
}
