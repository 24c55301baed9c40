// KdTreeSearch against pcl::search::KdTree (the reference it replaces) on the shared sensor
// clouds, with NaN points, indices, radius queries, and PCL's own estimator running on it.
#include <gtest/gtest.h>
#include <pcl/features/normal_3d.h>
#include <pcl/io/pcd_io.h>
#include <pcl/search/kdtree.h>

#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "estimator_support.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr loadCloud(const std::string& name) {
  Cloud::Ptr cloud(new Cloud);
  EXPECT_EQ(pcl::io::loadPCDFile(sharedData("clouds/" + name), *cloud), 0) << name;
  return cloud;
}

// Neighbour lists can legitimately differ in the order of points at the same distance, so they
// are compared as distances (exact) plus the set of indices strictly closer than the last one.
void expectSameNeighbours(const pcl::Indices& ours, const std::vector<float>& ours_d2,
                          const pcl::Indices& reference, const std::vector<float>& reference_d2,
                          const std::string& where) {
  ASSERT_EQ(ours.size(), reference.size()) << where;
  ASSERT_EQ(ours_d2.size(), ours.size()) << where;
  for (std::size_t j = 0; j < ours.size(); ++j) {
    ASSERT_FLOAT_EQ(ours_d2[j], reference_d2[j]) << where << " neighbour " << j;
    if (j > 0) ASSERT_LE(ours_d2[j - 1], ours_d2[j]) << where << " not sorted";
  }
  if (ours.empty()) return;
  const float last = reference_d2.back();
  std::vector<pcl::index_t> inner_ours, inner_reference;
  for (std::size_t j = 0; j < ours.size(); ++j) {
    if (ours_d2[j] < last) inner_ours.push_back(ours[j]);
    if (reference_d2[j] < last) inner_reference.push_back(reference[j]);
  }
  std::sort(inner_ours.begin(), inner_ours.end());
  std::sort(inner_reference.begin(), inner_reference.end());
  ASSERT_EQ(inner_ours, inner_reference) << where;
}

class KdTreeSearchOnSharedClouds : public ::testing::TestWithParam<std::string> {};

TEST_P(KdTreeSearchOnSharedClouds, KNearestAndRadiusMatchPCLsKdTree) {
  const Cloud::Ptr cloud = loadCloud(GetParam());
  ASSERT_GT(cloud->size(), 100u);
  KdTreeSearch<pcl::PointXYZ> ours;
  pcl::search::KdTree<pcl::PointXYZ> reference;
  ours.setInputCloud(cloud);
  reference.setInputCloud(cloud);

  // A radius of a few point spacings: the mean 8th-neighbour distance.
  double spacing = 0.0;
  int measured = 0;
  pcl::Indices a, b;
  std::vector<float> da, db;
  const std::size_t stride = std::max<std::size_t>(1, cloud->size() / 500);
  for (std::size_t i = 0; i < cloud->size(); i += stride) {
    if (!pcl::isXYZFinite((*cloud)[i])) continue;
    reference.nearestKSearch((*cloud)[i], 8, b, db);
    spacing += std::sqrt(db.back());
    ++measured;
  }
  ASSERT_GT(measured, 0);
  const double radius = spacing / measured;

  int queries = 0;
  for (std::size_t i = 0; i < cloud->size(); i += stride) {
    const pcl::PointXYZ& p = (*cloud)[i];
    if (!pcl::isXYZFinite(p)) continue;
    for (const int k : {1, 16, 50}) {
      ours.nearestKSearch(p, k, a, da);
      reference.nearestKSearch(p, k, b, db);
      expectSameNeighbours(a, da, b, db,
                           GetParam() + " k=" + std::to_string(k) + " at " + std::to_string(i));
    }
    ours.radiusSearch(p, radius, a, da);
    reference.radiusSearch(p, radius, b, db);
    expectSameNeighbours(a, da, b, db, GetParam() + " radius at " + std::to_string(i));
    ++queries;
  }
  EXPECT_GT(queries, 100);
}

TEST_P(KdTreeSearchOnSharedClouds, NeverReturnsNonFinitePoints) {
  const Cloud::Ptr cloud = loadCloud(GetParam());
  KdTreeSearch<pcl::PointXYZ> ours;
  ours.setInputCloud(cloud);
  pcl::Indices neighbours;
  std::vector<float> d2;
  std::size_t non_finite = 0;
  for (const auto& p : *cloud) non_finite += !pcl::isXYZFinite(p);
  const std::size_t stride = std::max<std::size_t>(1, cloud->size() / 200);
  for (std::size_t i = 0; i < cloud->size(); i += stride) {
    if (!pcl::isXYZFinite((*cloud)[i])) continue;
    ours.nearestKSearch((*cloud)[i], 30, neighbours, d2);
    for (const auto j : neighbours) ASSERT_TRUE(pcl::isXYZFinite((*cloud)[j])) << GetParam();
    for (const float d : d2) ASSERT_TRUE(std::isfinite(d));
  }
  // A query that is itself NaN finds nothing instead of garbage.
  pcl::PointXYZ nan_point;
  nan_point.x = nan_point.y = nan_point.z = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(ours.nearestKSearch(nan_point, 5, neighbours, d2), 0);
  EXPECT_TRUE(neighbours.empty());
  EXPECT_EQ(ours.radiusSearch(nan_point, 1.0, neighbours, d2), 0);
  std::cout << GetParam() << ": " << non_finite << " non-finite points of " << cloud->size()
            << "\n";
}

INSTANTIATE_TEST_SUITE_P(SharedClouds, KdTreeSearchOnSharedClouds,
                         ::testing::Values("bun0.pcd", "milk.pcd", "rs1.pcd",
                                           "table_scene_mug_stereo_textured.pcd"),
                         [](const auto& info) {
                           std::string name = info.param.substr(0, info.param.find('.'));
                           std::replace(name.begin(), name.end(), '_', 'X');
                           return name;
                         });

TEST(KdTreeSearch, WithIndicesSearchesOnlyThosePointsAndIndexQueriesFollowPCL) {
  const Eigen::Matrix3Xd grid = [] {
    Eigen::Matrix3Xd points(3, 100);
    for (int i = 0; i < 100; ++i) points.col(i) << i % 10, i / 10, 0.0;
    return points;
  }();
  const Cloud::Ptr cloud = toCloud(grid);
  auto even = std::make_shared<pcl::Indices>();
  for (int i = 0; i < 100; i += 2) even->push_back(i);

  KdTreeSearch<pcl::PointXYZ> ours;
  pcl::search::KdTree<pcl::PointXYZ> reference;
  ours.setInputCloud(cloud, even);
  reference.setInputCloud(cloud, even);
  pcl::Indices a, b;
  std::vector<float> da, db;
  for (int i = 0; i < 100; ++i) {
    ours.nearestKSearch((*cloud)[i], 6, a, da);
    for (const auto j : a) ASSERT_EQ(j % 2, 0) << "an index outside the searched set";
    reference.nearestKSearch((*cloud)[i], 6, b, db);
    expectSameNeighbours(a, da, b, db, "point " + std::to_string(i));
  }
  for (int i = 0; i < static_cast<int>(even->size()); ++i) {
    ours.nearestKSearch(i, 4, a, da);
    reference.nearestKSearch(i, 4, b, db);
    expectSameNeighbours(a, da, b, db, "index query " + std::to_string(i));
    ASSERT_EQ(a.front(), (*even)[i]) << "an index query means the i-th searched point";
  }
}

// A dense cloud searched whole is indexed where its points lie (no copy, ids its own); with every
// point given as indices it is copied first: the same answers, ties (a grid's) included, k
// nearest and radius, and for a cloud whose points moved after, the moved points once
// setInputCloud is called again.
TEST(KdTreeSearch, ACloudIndexedWhereItLiesAnswersAsItsCopy) {
  Eigen::Matrix3Xd grid(3, 900);
  for (int i = 0; i < 900; ++i) grid.col(i) << i % 30, (i / 30) % 30, 0.25 * (i % 7);
  const Cloud::Ptr cloud = toCloud(grid);
  auto all = std::make_shared<pcl::Indices>(900);
  std::iota(all->begin(), all->end(), 0);
  KdTreeSearch<pcl::PointXYZ> in_place, copied;
  in_place.setInputCloud(cloud);
  copied.setInputCloud(cloud, all);
  pcl::Indices a, b;
  std::vector<float> da, db;
  for (int i = 0; i < 900; ++i) {
    in_place.nearestKSearch((*cloud)[i], 13, a, da);
    copied.nearestKSearch((*cloud)[i], 13, b, db);
    ASSERT_EQ(a, b) << i;
    ASSERT_EQ(da, db) << i;
    in_place.radiusSearch((*cloud)[i], 1.5, a, da);
    copied.radiusSearch((*cloud)[i], 1.5, b, db);
    ASSERT_EQ(a, b) << i;
    ASSERT_EQ(da, db) << i;
  }
  for (auto& p : *cloud) p.x += 100.0f;
  in_place.setInputCloud(cloud);
  in_place.nearestKSearch(pcl::PointXYZ(100.0f, 0.0f, 0.0f), 1, a, da);
  EXPECT_EQ(a, pcl::Indices{0});
  EXPECT_EQ(da, std::vector<float>{0.0f});
}

TEST(KdTreeSearch, RadiusSearchCapsAtMaxNNWithTheNearestAndCountsMoreThanTheTree) {
  Eigen::Matrix3Xd line(3, 20);
  for (int i = 0; i < 20; ++i) line.col(i) << i, 0.0, 0.0;
  const Cloud::Ptr cloud = toCloud(line);
  KdTreeSearch<pcl::PointXYZ> ours;
  ours.setInputCloud(cloud);
  pcl::Indices neighbours;
  std::vector<float> d2;
  EXPECT_EQ(ours.radiusSearch((*cloud)[10], 3.5, neighbours, d2), 7);
  EXPECT_EQ(ours.radiusSearch((*cloud)[10], 3.5, neighbours, d2, 3), 3);
  EXPECT_EQ(d2, (std::vector<float>{0.f, 1.f, 1.f}));
  EXPECT_EQ(neighbours.front(), 10);
  // Asking for more neighbours than there are points gives all of them.
  EXPECT_EQ(ours.nearestKSearch((*cloud)[0], 100, neighbours, d2), 20);
  EXPECT_FLOAT_EQ(d2.back(), 19.f * 19.f);
  // An empty cloud answers nothing.
  ours.setInputCloud(Cloud::Ptr(new Cloud));
  EXPECT_EQ(ours.nearestKSearch((*cloud)[0], 5, neighbours, d2), 0);
  EXPECT_EQ(ours.radiusSearch((*cloud)[0], 5.0, neighbours, d2), 0);
}

TEST(KdTreeSearch, PCLsNormalEstimationRunsOnItUnchangedWithTheSameResult) {
  const Cloud::Ptr cloud = loadCloud("bun0.pcd");
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  estimation.setInputCloud(cloud);
  estimation.setKSearch(16);
  pcl::PointCloud<pcl::Normal> with_ours, with_pcl;
  estimation.setSearchMethod(std::make_shared<KdTreeSearch<pcl::PointXYZ>>());
  estimation.compute(with_ours);
  estimation.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  estimation.compute(with_pcl);
  ASSERT_EQ(with_ours.size(), with_pcl.size());
  const AngleErrors difference =
      angleErrors(normalsOf(with_ours), normalsOf(with_pcl), SignMode::Signed);
  EXPECT_EQ(difference.invalid, 0);
  EXPECT_LT(difference.max, 1e-3) << "degrees";
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
