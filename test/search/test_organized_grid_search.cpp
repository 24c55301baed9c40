// OrganizedGridSearch: pixel-grid neighbourhoods of organized clouds, checked against brute force
// over the window and on synthetic range images with a depth step.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>
#include <pcl/features/normal_3d.h>

#include <algorithm>
#include <cmath>

#include "pcl_ddg/search/organized_grid_search.h"
#include "range_images.h"

namespace pcl_ddg {
namespace {

using Search = OrganizedGridSearch<pcl::PointXYZ>;
using test::PinholeCamera;
using test::RangeScene;
using test::renderRangeImage;

pcl::index_t pixel(const pcl::PointCloud<pcl::PointXYZ>& cloud, int u, int v) {
  return static_cast<pcl::index_t>(v) * static_cast<pcl::index_t>(cloud.width) + u;
}

TEST(OrganizedGridSearch, RefusesUnorganizedCloudsAndBadSettings) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr line(new pcl::PointCloud<pcl::PointXYZ>(10, 1));
  Search search;
  EXPECT_THROW(search.setInputCloud(line), pcl::BadArgumentException);
  EXPECT_THROW(Search(0.0), pcl::BadArgumentException);
  EXPECT_THROW(Search(-1.0), pcl::BadArgumentException);
  EXPECT_THROW(Search(0.02, 0), pcl::BadArgumentException);
}

TEST(OrganizedGridSearch, NearestKAreTheNearestOfTheWindowQueryFirst) {
  const auto image = renderRangeImage(RangeScene::Plane, PinholeCamera{});
  auto search = std::make_shared<Search>();
  search->setInputCloud(image.cloud);
  pcl::Indices indices;
  std::vector<float> distances;
  const pcl::index_t query = pixel(*image.cloud, 80, 60);
  ASSERT_EQ(search->nearestKSearch(query, 12, indices, distances), 12);
  EXPECT_EQ(indices[0], query);
  EXPECT_EQ(distances[0], 0.0f);
  EXPECT_TRUE(std::is_sorted(distances.begin(), distances.end()));
  // Brute force over a window wide enough: the 12 nearest pixels of the whole plane.
  std::vector<float> all;
  for (int v = 50; v <= 70; ++v)
    for (int u = 70; u <= 90; ++u)
      all.push_back(((*image.cloud)[pixel(*image.cloud, u, v)].getVector3fMap() -
                     (*image.cloud)[query].getVector3fMap())
                        .squaredNorm());
  std::sort(all.begin(), all.end());
  for (int i = 0; i < 12; ++i) EXPECT_FLOAT_EQ(distances[i], all[i]) << i;
}

TEST(OrganizedGridSearch, RadiusSearchMatchesBruteForce) {
  const auto image = renderRangeImage(RangeScene::Sphere, PinholeCamera{});
  auto search = std::make_shared<Search>();
  search->setInputCloud(image.cloud);
  search->setSortedResults(true);
  const pcl::index_t query = pixel(*image.cloud, 80, 60);
  const double radius = 0.06;
  pcl::Indices indices;
  std::vector<float> distances;
  const int found = search->radiusSearch(query, radius, indices, distances);
  int expected = 0;
  for (std::size_t i = 0; i < image.cloud->size(); ++i) {
    const auto& p = (*image.cloud)[i];
    if (!std::isfinite(p.x)) continue;
    if ((p.getVector3fMap() - (*image.cloud)[query].getVector3fMap()).squaredNorm() <=
        static_cast<float>(radius * radius))
      ++expected;
  }
  EXPECT_GT(found, 20);
  EXPECT_EQ(found, expected);
  EXPECT_TRUE(std::is_sorted(distances.begin(), distances.end()));
  // max_nn keeps the nearest.
  pcl::Indices few;
  std::vector<float> few_distances;
  ASSERT_EQ(search->radiusSearch(query, radius, few, few_distances, 5), 5);
  for (int i = 0; i < 5; ++i) EXPECT_FLOAT_EQ(few_distances[i], distances[i]);
}

TEST(OrganizedGridSearch, NeverReturnsPixelsAcrossADepthJumpOrWithoutAPoint) {
  const auto image = renderRangeImage(RangeScene::BoxOnWall, PinholeCamera{});
  auto search = std::make_shared<Search>();
  search->setInputCloud(image.cloud);
  const auto& cloud = *image.cloud;
  int queries_at_the_step = 0;
  pcl::Indices indices;
  std::vector<float> distances;
  for (int v = 0; v < static_cast<int>(cloud.height); ++v) {
    for (int u = 0; u < static_cast<int>(cloud.width); ++u) {
      const pcl::index_t q = pixel(cloud, u, v);
      if (image.pixels_from_step[q] > 2) continue;
      ++queries_at_the_step;
      search->nearestKSearch(q, 16, indices, distances);
      ASSERT_EQ(indices.size(), 16u);
      const bool near_side = cloud[q].z < 2.9f;
      for (const pcl::index_t n : indices) {
        EXPECT_EQ(cloud[n].z < 2.9f, near_side) << "pixel " << u << "," << v;
      }
    }
  }
  EXPECT_GT(queries_at_the_step, 100);
  // A NaN query finds nothing, and NaN pixels are never found.
  auto holes = renderRangeImage(RangeScene::Sphere, PinholeCamera{});
  search->setInputCloud(holes.cloud);
  EXPECT_EQ(search->nearestKSearch(pixel(*holes.cloud, 0, 0), 5, indices, distances), 0);
  for (std::size_t i = 0; i < holes.cloud->size(); i += 7) {
    if (!std::isfinite((*holes.cloud)[i].x)) continue;
    search->nearestKSearch(static_cast<pcl::index_t>(i), 9, indices, distances);
    for (const pcl::index_t n : indices) EXPECT_TRUE(std::isfinite((*holes.cloud)[n].x));
  }
}

TEST(OrganizedGridSearch, KLargerThanAnIslandReturnsTheIsland) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>(40, 40));
  for (auto& p : *cloud) p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
  for (int v = 10; v < 12; ++v)
    for (int u = 10; u < 13; ++u) (*cloud)(u, v) = pcl::PointXYZ(0.01f * u, 0.01f * v, 1.0f);
  Search search;
  search.setInputCloud(cloud);
  pcl::Indices indices;
  std::vector<float> distances;
  EXPECT_EQ(search.nearestKSearch(pixel(*cloud, 10, 10), 50, indices, distances), 6);
}

TEST(OrganizedGridSearch, ServesPclNormalEstimation) {
  // Any PCL feature can use the grid: pcl::NormalEstimation on the plane gives its normal.
  const auto image = renderRangeImage(RangeScene::Plane, PinholeCamera{});
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  estimation.setInputCloud(image.cloud);
  estimation.setSearchMethod(std::make_shared<Search>());
  estimation.setKSearch(9);
  pcl::PointCloud<pcl::Normal> normals;
  estimation.compute(normals);
  ASSERT_EQ(normals.size(), image.cloud->size());
  EXPECT_EQ(normals.width, image.cloud->width);
  for (std::size_t i = 0; i < normals.size(); i += 13) {
    const Eigen::Vector3d n = normals[i].getNormalVector3fMap().cast<double>();
    EXPECT_NEAR(std::abs(n.dot(image.normals[i])), 1.0, 1e-5) << i;
  }
}

}  // namespace
}  // namespace pcl_ddg
