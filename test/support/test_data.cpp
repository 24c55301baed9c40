#include "test_data.h"

#include <gtest/gtest.h>
#include <pcl/conversions.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <vector>

namespace pcl_ddg {
namespace test {

std::string sharedData(const std::string& relative_path) {
  const std::string root = PCL_DDG_SHARED_DATA_DIR;
  if (root.empty() || !std::filesystem::exists(root + "/CATALOG.md")) {
    ADD_FAILURE() << "shared data folder not found (configure with -DPCL_DDG_SHARED_DATA_DIR=...)";
    throw std::runtime_error("shared data missing");
  }
  return root + "/" + relative_path;
}

namespace {

// The scratch folders this process made, removed when the test program ends (gtest's global
// tear-down) if every test passed; after a failure they are kept, and their paths printed, for
// a look at the files.
class ScratchFolders : public ::testing::Environment {
 public:
  static ScratchFolders& instance() {
    // Owned by gtest once registered (it deletes its environments at exit).
    static ScratchFolders* const folders = [] {
      auto* environment = new ScratchFolders;
      ::testing::AddGlobalTestEnvironment(environment);
      return environment;
    }();
    return *folders;
  }
  void add(const std::filesystem::path& path) {
    const std::lock_guard<std::mutex> lock(mutex_);
    paths_.push_back(path);
  }
  void TearDown() override {
    const std::lock_guard<std::mutex> lock(mutex_);
    const bool passed = ::testing::UnitTest::GetInstance()->Passed();
    for (const auto& path : paths_) {
      if (passed) {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
      } else if (std::filesystem::exists(path)) {
        std::printf("a test failed: its scratch folder %s is kept\n", path.c_str());
      }
    }
    paths_.clear();
  }

 private:
  std::mutex mutex_;
  std::vector<std::filesystem::path> paths_;
};

// Registered before RUN_ALL_TESTS (at static initialisation), as gtest requires; a program that
// never asks for a scratch folder gets an environment with nothing to remove.
[[maybe_unused]] const ScratchFolders& kScratchFolders = ScratchFolders::instance();

}  // namespace

std::string scratchFolder(const std::string& name) {
  // The process id keeps concurrent runs (a release and a sanitizer build, two clones) apart.
  const auto path = std::filesystem::temp_directory_path() /
                    ("pcl_ddg_test_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(path);
  std::filesystem::create_directories(path);
  ScratchFolders::instance().add(path);
  return path.string();
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

pcl::PolygonMesh makeMesh(const Eigen::Matrix3Xd& positions,
                          const std::vector<std::vector<int>>& polygons) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    cloud.push_back(pcl::PointXYZ(static_cast<float>(positions(0, i)),
                                  static_cast<float>(positions(1, i)),
                                  static_cast<float>(positions(2, i))));
  }
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(cloud, mesh.cloud);
  for (const auto& p : polygons) {
    pcl::Vertices v;
    v.vertices.assign(p.begin(), p.end());
    mesh.polygons.push_back(v);
  }
  return mesh;
}

}  // namespace test
}  // namespace pcl_ddg
