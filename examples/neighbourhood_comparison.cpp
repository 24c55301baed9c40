// The same PCA normal estimated with mesh-ring (topological) and kd-tree (Euclidean)
// neighbourhoods, and how much they disagree.
//   example_neighbourhood_comparison mesh.ply
#include <pcl/conversions.h>

#include <iostream>

#include "pcl_ddg/features/neighbourhood_comparison.h"
#include "pcl_ddg/io/mesh_io.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " mesh.{ply,obj,off,stl,vtk}\n";
    return 2;
  }
  const pcl::PolygonMesh mesh = pcl_ddg::loadMesh(argv[1]);
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::fromPCLPointCloud2(mesh.cloud, *cloud);
  pcl_ddg::LocalFitOptions options;
  options.method = pcl_ddg::LocalFitMethod::PCA;
  options.k = 16;
  const pcl_ddg::NeighbourhoodComparison comparison = pcl_ddg::compareNeighbourhoods(
      cloud, std::make_shared<const pcl_ddg::MeshTopology>(mesh), options);
  const auto& s = comparison.summary;
  std::cout << s.compared << " vertices: angle difference mean " << s.mean
            << " deg, 95th percentile " << s.percentile95 << " deg; neighbour overlap "
            << s.mean_overlap << "\n";
  return 0;
}
