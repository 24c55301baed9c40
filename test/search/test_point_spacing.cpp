// What a cloud's sampling supports: the coordinate quantum against the spacing (a float far from
// the origin is a lattice), and the points a radius holds. Oracles: grids built with a known
// step and a known float rounding, and brute-force counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "pcl_ddg/search/point_spacing.h"

namespace pcl_ddg {
namespace {

/** A jittered grid of n x n points with the given step, placed at `offset`, stored in float. */
pcl::PointCloud<pcl::PointXYZ> jitteredGrid(int n, double step, const Eigen::Vector3d& offset) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.2 * step, 0.2 * step);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d p =
          offset + Eigen::Vector3d(i * step + jitter(random), j * step + jitter(random),
                                   0.1 * std::sin(i * step) + jitter(random));
      cloud.push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                    static_cast<float>(p.z())));
    }
  }
  return cloud;
}

TEST(PointSpacing, AFloatCloudAtUTMNorthingsIsALatticeOfHalfAMetre) {
  // Points 0.1 m apart at y = 5.4e6: a float there is a multiple of 0.5 (2^22 <= y < 2^23).
  const pcl::PointCloud<pcl::PointXYZ> utm = jitteredGrid(200, 0.1, {5.1e5, 5.4e6, 300.0});
  const PointSpacing far = measurePointSpacing(utm);
  EXPECT_EQ(far.quantum, 0.5);
  EXPECT_TRUE(far.quantised()) << far.median_spacing;
  // The same points near the origin: a float's step is 1e-7 of a metre there.
  const pcl::PointCloud<pcl::PointXYZ> near = jitteredGrid(200, 0.1, {10.0, 20.0, 30.0});
  const PointSpacing fine = measurePointSpacing(near);
  EXPECT_LE(fine.quantum, std::ldexp(1.0, -18));
  EXPECT_FALSE(fine.quantised());
}

TEST(PointSpacing, TheSpacingIsTheMedianDistanceToTheNearestDistinctPoint) {
  // A regular grid of step 0.25 (exact in float) with every point doubled: duplicates do not
  // count, the spacing is the step. The quantum is decided first (1e-5 of the diagonal), so the
  // grid is coarse enough for the spacing to be measured.
  pcl::PointCloud<pcl::PointXYZ> grid;
  for (int i = 0; i < 50; ++i)
    for (int j = 0; j < 50; ++j)
      for (int copy = 0; copy < 2; ++copy) grid.push_back(pcl::PointXYZ(0.25f * i, 0.25f * j, 0));
  // All finite: the kd-tree is over the points where they lie; with a NaN, over a copy of the rest.
  EXPECT_EQ(measurePointSpacing(grid).median_spacing, 0.25);
  grid.push_back(pcl::PointXYZ(NAN, 0, 0));  // non-finite points take no part
  const PointSpacing spacing = measurePointSpacing(grid);
  EXPECT_EQ(spacing.quantum, 0.25);
  EXPECT_EQ(spacing.median_spacing, 0.25);
  EXPECT_TRUE(spacing.quantised()) << "a lattice at its own spacing";
  EXPECT_EQ(measurePointSpacing(pcl::PointCloud<pcl::PointXYZ>()).quantum, 0.0);
}

TEST(PointSpacing, TheMedianSpacingOfALatticedCloudIsTheBruteForceOne) {
  // A float cloud at UTM northings (a 0.5 lattice: the spacing is measured), every point finite
  // (the kd-tree reads them where they lie) and fewer than the samples (every point counts): the
  // median over the points of the distance to the nearest distinct other, by brute force.
  const pcl::PointCloud<pcl::PointXYZ> utm = jitteredGrid(40, 0.1, {5.1e5, 5.4e6, 300.0});
  std::vector<double> nearest;
  for (const pcl::PointXYZ& p : utm) {
    float closest = std::numeric_limits<float>::infinity();
    for (const pcl::PointXYZ& q : utm) {
      const float d = (p.getVector3fMap() - q.getVector3fMap()).squaredNorm();
      if (d > 0.0f) closest = std::min(closest, d);
    }
    nearest.push_back(std::sqrt(static_cast<double>(closest)));
  }
  std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
  const PointSpacing spacing = measurePointSpacing(utm);
  ASSERT_TRUE(spacing.quantised());
  EXPECT_NEAR(spacing.median_spacing, nearest[nearest.size() / 2], 1e-6);
}

TEST(PointSpacing, RadiusCountsAgreeWithBruteForce) {
  const pcl::PointCloud<pcl::PointXYZ> cloud = jitteredGrid(60, 0.1, {1.0, 2.0, 3.0});
  const double radius = 0.15;
  const int min_nn = 12;
  // Every point sampled (samples >= size): the counts are every point's.
  const RadiusNeighbourCounts counts = countRadiusNeighbours(cloud, radius, min_nn, 1 << 20);
  std::vector<long> inside(cloud.size());
  std::vector<double> reach(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::vector<double> d;
    for (std::size_t j = 0; j < cloud.size(); ++j)
      d.push_back((cloud[i].getVector3fMap() - cloud[j].getVector3fMap()).squaredNorm());
    inside[i] = std::count_if(d.begin(), d.end(), [&](double x) { return x < radius * radius; });
    std::nth_element(d.begin(), d.begin() + (min_nn - 1), d.end());
    reach[i] = std::sqrt(d[min_nn - 1]);
  }
  EXPECT_EQ(counts.sampled, static_cast<long>(cloud.size()));
  EXPECT_EQ(counts.min, *std::min_element(inside.begin(), inside.end()));
  std::vector<long> sorted = inside;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  EXPECT_EQ(counts.median, sorted[sorted.size() / 2]);
  EXPECT_EQ(counts.share_under_3, std::count_if(inside.begin(), inside.end(), [](long c) {
                                    return c < 3;
                                  }) / static_cast<double>(inside.size()));
  std::nth_element(reach.begin(), reach.begin() + reach.size() * 9 / 10, reach.end());
  EXPECT_NEAR(counts.radius_for_min_neighbours, reach[reach.size() * 9 / 10], 1e-6);
  // At that radius, 90 % of the points do hold min_nn (up to ties at the boundary).
  const RadiusNeighbourCounts there =
      countRadiusNeighbours(cloud, counts.radius_for_min_neighbours * 1.0001, min_nn, 1 << 20);
  EXPECT_GE(there.median, min_nn);
  EXPECT_THROW(countRadiusNeighbours(cloud, 0.0, 3), pcl::BadArgumentException);
  EXPECT_THROW(countRadiusNeighbours(cloud, 1.0, 0), pcl::BadArgumentException);
}

}  // namespace
}  // namespace pcl_ddg
