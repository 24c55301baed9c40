#include "data_catalogue.h"

namespace pcl_ddg {
namespace test {

const std::vector<SharedMesh>& sharedMeshes() {
  static const std::vector<SharedMesh> meshes = {
      {"meshes/bumpy.off", 1250, 2496, 0, 0, 0, 0},
      {"meshes/bun045_rangegrid_tri.ply", 40097, 79057, 1137, 0, 0, 6},
      {"meshes/bun_zipper.ply", 35947, 69451, 223, 0, 0, 1113},
      {"meshes/bun_zipper_res3.ply", 1889, 3851, 60, 141, 83, 2},
      {"meshes/bun_zipper_res4.ply", 453, 948, 26, 70, 40, 0},
      {"meshes/bunny.off", 3485, 6966, 0, 0, 0, 0},
      {"meshes/cow.off", 2762, 5520, 0, 0, 0, 0},
      {"meshes/horse.ply", 48485, 96966, 0, 0, 0, 0},
      {"meshes/igea.ply", 134345, 268686, 0, 0, 0, 0},
      {"meshes/rocker-arm.off", 10044, 20088, 0, 0, 0, 0},
      {"meshes/tum_rabbit.vtk", 10429, 20715, 141, 0, 0, 0},
  };
  return meshes;
}

const std::vector<SharedCloud>& sharedClouds() {
  static const std::vector<SharedCloud> clouds = {
      {"clouds/bun0.pcd", 397},
      {"clouds/milk.pcd", 13704},
      {"clouds/office1.pcd", 307200},
      {"clouds/rs1.pcd", 289541},
      {"clouds/table_scene_mug_stereo_textured.pcd", 307200},
      {"clouds/terrain_CSite1_red2-utm.pcd", 131622},
      {"clouds/tutorials_room_scan1.pcd", 112586},
  };
  return clouds;
}

const std::vector<SharedCloud>& sharedLasFiles() {
  static const std::vector<SharedCloud> files = {
      {"las/autzen_trim.las", 110000},
      {"las/extrabytes.las", 1065},
      {"las/test1_4.las", 1000},
  };
  return files;
}

}  // namespace test
}  // namespace pcl_ddg
