// Normal estimation with topological neighbourhoods, the pcl_ddg version of PCL's tutorial
// "Estimating Surface Normals in a PointCloud": the same pcl::Feature calls, with the k nearest
// vertices found by a breadth-first search over the mesh instead of a kd-tree.
//   example_normal_estimation_mesh_rings mesh.ply
#include <pcl/PolygonMesh.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <iostream>

#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/search/mesh_ring_search.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " mesh.{ply,obj,off,stl,vtk}\n";
    return 2;
  }
  const pcl::PolygonMesh mesh = pcl_ddg::loadMesh(argv[1]);
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::fromPCLPointCloud2(mesh.cloud, *cloud);

  pcl_ddg::PCANormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
  estimator.setInputCloud(cloud);
  // Neighbours along the surface: a thin part's other side is never mistaken for a neighbour.
  estimator.setSearchMethod(std::make_shared<pcl_ddg::MeshRingSearch<pcl::PointXYZ>>(mesh));
  estimator.setKSearch(16);
  pcl::PointCloud<pcl::Normal> normals;
  estimator.compute(normals);

  std::cout << normals.size()
            << " normals; the first: " << normals[0].getNormalVector3fMap().transpose() << "\n";
  return normals.size() == cloud->size() ? 0 : 1;
}
