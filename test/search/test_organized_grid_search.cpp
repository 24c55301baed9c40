// OrganizedGridSearch: pixel-grid neighbourhoods of organized clouds, checked against brute force
// over the window and on synthetic range images with a depth step.
#include <gtest/gtest.h>
#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>
#include <pcl/features/normal_3d.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "pcl_ddg/search/organized_grid_search.h"
#include "range_images.h"
#include "test_data.h"

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

// windowSearch against the test's own flood fill of the header's rule (test::WindowReachOracle):
// the same pixels, the query first, each with its squared distance. On the synthetic frames every
// pixel (the box's 5 % step and the sphere's limb cut windows), the scene 1e5 from the origin
// (ranges are measured from the sensor origin, not the coordinates' origin: from there the box's
// step would be 0.1 % of the range, and no window would be cut), and every 5th pixel of a Kinect
// frame (holes and steps everywhere).
TEST(OrganizedGridSearch, WindowSearchReachesExactlyThePixelsOfABruteForceFloodFill) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr office(new pcl::PointCloud<pcl::PointXYZ>);
  ASSERT_EQ(pcl::io::loadPCDFile(test::sharedData("clouds/office1.pcd"), *office), 0);
  const struct {
    const char* name;
    pcl::PointCloud<pcl::PointXYZ>::ConstPtr cloud;
    int every;
  } frames[] = {
      {"box on wall", renderRangeImage(RangeScene::BoxOnWall, PinholeCamera{}).cloud, 1},
      {"sphere", renderRangeImage(RangeScene::Sphere, PinholeCamera{}, 2e-3, 7).cloud, 1},
      {"box on wall far from the origin",
       renderRangeImage(RangeScene::BoxOnWall, PinholeCamera{}, 0.0, 1, {1e5, -1e5, 1e5}).cloud, 1},
      {"office1.pcd", office, 5}};
  for (const auto& frame : frames) {
    SCOPED_TRACE(frame.name);
    Search search;
    search.setInputCloud(frame.cloud);
    const test::WindowReachOracle oracle(*frame.cloud, search.maxDepthJump());
    pcl::Indices found;
    std::vector<float> distances;
    for (const int radius : {1, 3, 5}) {
      SCOPED_TRACE(radius);
      int compared = 0, cut = 0, ambiguous = 0;
      for (std::size_t i = 0; i < frame.cloud->size(); i += frame.every) {
        bool near_threshold = false;
        const std::vector<int> expected =
            oracle.reach(static_cast<int>(i), radius, &near_threshold);
        if (near_threshold) {
          ++ambiguous;
          continue;
        }
        const int n = search.windowSearch(static_cast<pcl::index_t>(i), radius, found, distances);
        ASSERT_EQ(n, static_cast<int>(expected.size())) << "pixel " << i;
        ASSERT_EQ(found.size(), expected.size()) << "pixel " << i;
        ASSERT_EQ(distances.size(), expected.size()) << "pixel " << i;
        ASSERT_EQ(search.windowReach(static_cast<pcl::index_t>(i), radius), n) << "pixel " << i;
        if (expected.empty()) continue;
        ++compared;
        EXPECT_EQ(found[0], static_cast<pcl::index_t>(i));
        std::vector<int> sorted(found.begin(), found.end());
        std::sort(sorted.begin(), sorted.end());
        ASSERT_EQ(sorted, expected) << "pixel " << i;
        const auto& cloud = *frame.cloud;
        for (std::size_t k = 0; k < found.size(); ++k) {
          EXPECT_FLOAT_EQ(
              distances[k],
              (cloud[found[k]].getVector3fMap() - cloud[i].getVector3fMap()).squaredNorm());
        }
        // A cut window: fewer pixels reached than the window holds with finite points.
        const int u = static_cast<int>(i % cloud.width), v = static_cast<int>(i / cloud.width);
        int finite = 0;
        for (int y = std::max(0, v - radius); y <= std::min<int>(cloud.height - 1, v + radius); ++y)
          for (int x = std::max(0, u - radius); x <= std::min<int>(cloud.width - 1, u + radius);
               ++x)
            finite += pcl::isXYZFinite(cloud(x, y));
        cut += n < finite;
      }
      std::printf("%s, radius %d: %d windows, %d cut, %d with a step at the threshold\n",
                  frame.name, radius, compared, cut, ambiguous);
      EXPECT_GT(compared, 1000);
      EXPECT_GT(cut, 50) << "no depth jump cut a window";
      // A step at the threshold leaves out every window holding it (up to (2r + 1)^2 / 5 here).
      EXPECT_LE(ambiguous, compared / 200);
    }
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
