// The visiting order of the estimators: a permutation, non-finite points last, and consecutive
// points near each other even when the cloud is stored in random order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "pcl_ddg/features/spatial_order.h"

namespace pcl_ddg {
namespace test {
namespace {

double meanStep(const std::vector<Eigen::Vector3f>& p, const std::vector<int>& order) {
  double sum = 0.0;
  int steps = 0;
  for (std::size_t j = 1; j < order.size(); ++j) {
    if (!p[order[j]].allFinite() || !p[order[j - 1]].allFinite()) continue;
    sum += (p[order[j]] - p[order[j - 1]]).norm();
    ++steps;
  }
  return sum / steps;
}

TEST(SpatialOrder, IsAPermutationWithNonFinitePointsLastAndShortSteps) {
  // A 200 x 200 grid of a unit square, stored shuffled, with a few NaN points among it.
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 200; ++j) points.emplace_back(i / 200.0f, j / 200.0f, 0.0f);
  std::shuffle(points.begin(), points.end(), std::mt19937(5));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i : {7, 100, 39999}) points[i] = Eigen::Vector3f(nan, 0.0f, 0.0f);

  const std::vector<int> order = detail::spatialOrder(points);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> identity(points.size());
  std::iota(identity.begin(), identity.end(), 0);
  EXPECT_EQ(sorted, identity);
  for (std::size_t j = order.size() - 3; j < order.size(); ++j)
    EXPECT_FALSE(points[order[j]].allFinite());

  // Stored order: steps of about half the square; visiting order: a few grid spacings.
  const double stored = meanStep(points, identity), visited = meanStep(points, order);
  std::printf("mean step: %.4f stored, %.4f in spatial order (spacing 0.005)\n", stored, visited);
  EXPECT_GT(stored, 0.3);
  EXPECT_LT(visited, 0.02);
}

TEST(SpatialOrder, DegenerateInputs) {
  EXPECT_TRUE(detail::spatialOrder({}).empty());
  const std::vector<Eigen::Vector3f> same(5, Eigen::Vector3f(1, 2, 3));
  std::vector<int> order = detail::spatialOrder(same);
  std::sort(order.begin(), order.end());
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
