// Implicit Laplacian smoothing of a mesh (one backward-Euler step of 2 h^2, h the mean edge
// length), through the mesh-processor interface shaped like pcl::MeshProcessing.
//   example_smoothing mesh.ply smoothed.ply
#include <iostream>

#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: " << argv[0] << " input.ply output.ply\n";
    return 2;
  }
  auto input = std::make_shared<pcl::PolygonMesh>(pcl_ddg::loadMesh(argv[1]));
  const double h = pcl_ddg::meanEdgeLength(pcl_ddg::MeshTopology(*input),
                                           pcl_ddg::vertexPositions(input->cloud));

  pcl_ddg::MeshSmoothing smoothing;
  smoothing.setInputMesh(input);
  smoothing.setScheme(pcl_ddg::SmoothingScheme::Implicit);
  smoothing.setTimeStep(2.0 * h * h);
  pcl::PolygonMesh output;
  smoothing.process(output);
  pcl_ddg::saveMesh(argv[2], output);

  const pcl_ddg::MeshSmoothingReport& report = smoothing.getReport();
  std::cout << "area " << report.area_before << " -> " << report.area_after << ", smallest angle "
            << report.quality_before.min_angle_degrees << " -> "
            << report.quality_after.min_angle_degrees << " deg\n";
  return 0;
}
