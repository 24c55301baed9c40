#pragma once
// The shared data the tests read (../shared/data, see its CATALOG.md), with what the catalogue says
// of each file, counted independently of this project. Every test that runs over "every shared
// mesh" or "every shared cloud" takes its list from here.
#include <string>
#include <vector>

namespace pcl_ddg {
namespace test {

struct SharedMesh {
  const char* path;  ///< under the shared data folder (sharedData)
  int vertices, faces, boundary_edges, nonmanifold_edges, duplicate_faces, unreferenced_vertices;
};

struct SharedCloud {
  const char* path;
  int points;
};

/** The meshes under meshes/. */
const std::vector<SharedMesh>& sharedMeshes();
/** The sensor clouds under clouds/ (PCD). */
const std::vector<SharedCloud>& sharedClouds();
/** The LAS files that are whole (las/: not the truncated clip, not the LAZ). */
const std::vector<SharedCloud>& sharedLasFiles();

}  // namespace test
}  // namespace pcl_ddg
