#pragma once
// Where the real scans live, and the meshes the tests build by hand.
#include <pcl/PolygonMesh.h>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace pcl_ddg {
namespace test {

/** Path of a file under the shared data folder; fails the test loudly if the folder is missing. */
std::string sharedData(const std::string& relative_path);

/** A fresh empty folder for a test's files. */
std::string scratchFolder(const std::string& name);

/** Writes text to a file (for hand-made inputs). */
void writeText(const std::string& path, const std::string& text);

/** A PCL mesh from positions (float x, y, z fields) and polygons. */
pcl::PolygonMesh makeMesh(const Eigen::Matrix3Xd& positions,
                          const std::vector<std::vector<int>>& polygons);

}  // namespace test
}  // namespace pcl_ddg
