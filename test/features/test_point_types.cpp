// The estimators and searches link and agree for every PCL point type scan users have (the list in
// pcl_ddg/point_types.h), without PCL_NO_PRECOMPILE: each gives the PointXYZ result bit for bit.
#include <gtest/gtest.h>

#include <cstring>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/features/quadric_normal_estimation.h"
#include "pcl_ddg/point_types.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "pcl_ddg/search/mesh_ring_search.h"

namespace pcl_ddg {
namespace test {
namespace {

const SurfaceSample& sphere() {
  static const SurfaceSample s = makeIcosphere(3, 1.0, 0.1);
  return s;
}

template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr cloudOf(const Eigen::Matrix3Xd& points) {
  auto cloud = std::make_shared<pcl::PointCloud<PointT>>();
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    PointT p;
    p.x = static_cast<float>(points(0, i));
    p.y = static_cast<float>(points(1, i));
    p.z = static_cast<float>(points(2, i));
    cloud->push_back(p);
  }
  return cloud;
}

// The normal (and curvature) of every point, as raw bytes of the xyz-independent fields.
template <typename PointT, typename NormalT, template <typename, typename> class Estimator>
std::vector<float> estimate(typename pcl::search::Search<PointT>::Ptr search) {
  Estimator<PointT, NormalT> estimator;
  estimator.setInputCloud(cloudOf<PointT>(sphere().points));
  estimator.setSearchMethod(search);
  estimator.setKSearch(12);
  pcl::PointCloud<NormalT> out;
  estimator.compute(out);
  std::vector<float> values;
  for (const NormalT& n : out) {
    values.insert(values.end(), {n.normal_x, n.normal_y, n.normal_z, n.curvature});
  }
  return values;
}

template <typename PointT>
class ScanPointTypes : public ::testing::Test {};
using Types = ::testing::Types<pcl::PointXYZ, pcl::PointXYZI, pcl::PointXYZRGB, pcl::PointXYZRGBA,
                               pcl::PointNormal, pcl::PointXYZINormal, pcl::PointXYZRGBNormal>;
TYPED_TEST_SUITE(ScanPointTypes, Types);

TYPED_TEST(ScanPointTypes, EstimatorsAndSearchesGiveThePointXYZResults) {
  using P = TypeParam;
  const auto topology = topologyPtrOf(sphere());
  const auto rings = [&] { return std::make_shared<MeshRingSearch<P>>(topology); };
  const auto tree = [] { return std::make_shared<KdTreeSearch<P>>(); };
  const auto xyz_rings = [&] { return std::make_shared<MeshRingSearch<pcl::PointXYZ>>(topology); };
  const auto xyz_tree = [] { return std::make_shared<KdTreeSearch<pcl::PointXYZ>>(); };

  const auto pca = estimate<P, pcl::Normal, PCANormalEstimation>(tree());
  ASSERT_EQ(pca.size(), 4 * static_cast<std::size_t>(sphere().points.cols()));
  EXPECT_EQ(pca, (estimate<pcl::PointXYZ, pcl::Normal, PCANormalEstimation>(xyz_tree())));
  EXPECT_EQ((estimate<P, pcl::PointXYZINormal, PCANormalEstimation>(rings())),
            (estimate<pcl::PointXYZ, pcl::Normal, PCANormalEstimation>(xyz_rings())));
  EXPECT_EQ((estimate<P, pcl::PointNormal, QuadricNormalEstimation>(rings())),
            (estimate<pcl::PointXYZ, pcl::Normal, QuadricNormalEstimation>(xyz_rings())));
  EXPECT_EQ((estimate<P, pcl::PointXYZRGBNormal, QuadricNormalEstimation>(tree())),
            (estimate<pcl::PointXYZ, pcl::Normal, QuadricNormalEstimation>(xyz_tree())));
  for (std::size_t i = 0; i < pca.size(); i += 4) {
    ASSERT_NEAR(std::sqrt(pca[i] * pca[i] + pca[i + 1] * pca[i + 1] + pca[i + 2] * pca[i + 2]), 1.0,
                1e-5);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
