#pragma once
// Where the real scans live, and the meshes the tests build by hand.
#include <pcl/PolygonMesh.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#define PCL_DDG_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PCL_DDG_UNDER_ASAN 1
#endif
#endif

namespace pcl_ddg {
namespace test {

/** AddressSanitizer's shadow memory and quarantine make memory peaks meaningless. */
#ifdef PCL_DDG_UNDER_ASAN
constexpr bool kUnderAddressSanitizer = true;
#else
constexpr bool kUnderAddressSanitizer = false;
#endif

/** Path of a file under the shared data folder; fails the test loudly if the folder is missing. */
std::string sharedData(const std::string& relative_path);

/** A fresh empty folder for a test's files (its name holds the process id), removed when the test
 *  program ends unless a test failed (then its path is printed). */
std::string scratchFolder(const std::string& name);

/** Writes text to a file (for hand-made inputs). */
void writeText(const std::string& path, const std::string& text);

/** A file's bytes (empty if it cannot be read). */
std::string readBytes(const std::string& path);

/** A PCL mesh from positions (float x, y, z fields) and polygons. */
pcl::PolygonMesh makeMesh(const Eigen::Matrix3Xd& positions,
                          const std::vector<std::vector<int>>& polygons);

}  // namespace test
}  // namespace pcl_ddg
