// A point type of the user's own (not in pcl_ddg/point_types.h) works with PCL_NO_PRECOMPILE, as
// in PCL: the templates are compiled here, and give the PointXYZ results of the library.
#define PCL_NO_PRECOMPILE
#include <gtest/gtest.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "pcl_ddg/search/mesh_ring_search.h"

namespace scanner {
struct EIGEN_ALIGN16 ReturnPoint {
  PCL_ADD_POINT4D;
  float reflectance;
  std::uint16_t ring;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};
}  // namespace scanner
POINT_CLOUD_REGISTER_POINT_STRUCT(scanner::ReturnPoint,
                                  (float, x, x)(float, y, y)(float, z, z)(
                                      float, reflectance, reflectance)(std::uint16_t, ring, ring))

namespace pcl_ddg {
namespace test {
namespace {

TEST(CustomPointType, EstimatorAndSearchesWorkWithPclNoPrecompile) {
  const SurfaceSample sphere = makeIcosphere(3, 1.0, 0.1);
  auto cloud = std::make_shared<pcl::PointCloud<scanner::ReturnPoint>>();
  for (Eigen::Index i = 0; i < sphere.points.cols(); ++i) {
    scanner::ReturnPoint p;
    p.x = static_cast<float>(sphere.points(0, i));
    p.y = static_cast<float>(sphere.points(1, i));
    p.z = static_cast<float>(sphere.points(2, i));
    p.reflectance = 0.5f;
    p.ring = static_cast<std::uint16_t>(i % 16);
    cloud->push_back(p);
  }
  const auto topology = topologyPtrOf(sphere);
  for (const bool rings : {false, true}) {
    PCANormalEstimation<scanner::ReturnPoint, pcl::Normal> custom;
    PCANormalEstimation<pcl::PointXYZ, pcl::Normal> xyz;
    custom.setInputCloud(cloud);
    xyz.setInputCloud(toCloud(sphere.points));
    if (rings) {
      custom.setSearchMethod(std::make_shared<MeshRingSearch<scanner::ReturnPoint>>(topology));
      xyz.setSearchMethod(std::make_shared<MeshRingSearch<pcl::PointXYZ>>(topology));
    } else {
      custom.setSearchMethod(std::make_shared<KdTreeSearch<scanner::ReturnPoint>>());
      xyz.setSearchMethod(std::make_shared<KdTreeSearch<pcl::PointXYZ>>());
    }
    custom.setKSearch(12);
    xyz.setKSearch(12);
    pcl::PointCloud<pcl::Normal> a, b;
    custom.compute(a);
    xyz.compute(b);
    ASSERT_EQ(a.size(), b.size());
    const Eigen::Matrix3Xd na = normalsOf(a), nb = normalsOf(b);
    EXPECT_EQ(na, nb) << (rings ? "mesh rings" : "kd-tree");
    EXPECT_TRUE(na.allFinite());
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
