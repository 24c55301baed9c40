// Stopping a long computation (interruption.h): a check installed for the calling thread is run
// by the loops from that thread, and once it says stop the call throws InterruptedException.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <random>

#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/interruption.h"
#include "pcl_ddg/mesh/local_cloud.h"

namespace pcl_ddg {
namespace {

using Clock = std::chrono::steady_clock;

Eigen::Matrix3Xd randomPoints(int n) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Eigen::Matrix3Xd points(3, n);
  for (Eigen::Index i = 0; i < points.size(); ++i) points.data()[i] = uniform(random);
  return points;
}

LocalFitOptions nearest(int k) {
  LocalFitOptions options;
  options.method = LocalFitMethod::PCA;
  options.neighbourhood = NeighbourhoodKind::KdTree;
  options.k = k;
  return options;
}

// Polls as a loop does, until it stops (true) or the deadline passes (false).
bool pollUntil(Clock::duration deadline) {
  detail::InterruptionPoll poll;
  const auto end = Clock::now() + deadline;
  while (Clock::now() < end)
    if (poll.stopped()) return true;
  return false;
}

TEST(Interruption, ACheckThatSaysStopEndsAFitWithInterruptedException) {
  // k = 2000 of 20,000 points: seconds of work, polled every 0.1 s of it.
  const LocalCloud cloud = makeLocalCloud(randomPoints(20000));
  std::atomic<int> checks{0};
  const InterruptionScope scope([&] { return ++checks >= 2; });
  EXPECT_THROW(fitLocalSurfaces(cloud, nullptr, nearest(2000)), InterruptedException);
  EXPECT_EQ(checks.load(), 2);  // run until it said stop, never again after
}

TEST(Interruption, ACheckThatNeverStopsChangesNoBit) {
  const LocalCloud cloud = makeLocalCloud(randomPoints(4000));
  const LocalFitResult plain = fitLocalSurfaces(cloud, nullptr, nearest(400));
  std::atomic<int> checks{0};
  LocalFitResult checked;
  {
    const InterruptionScope scope([&] {
      ++checks;
      return false;
    });
    checked = fitLocalSurfaces(cloud, nullptr, nearest(400));
  }
  ASSERT_EQ(checked.normals.size(), plain.normals.size());
  for (std::size_t i = 0; i < plain.normals.size(); ++i) {
    const pcl::Normal &a = plain.normals[i], &b = checked.normals[i];
    const float x[4] = {a.normal_x, a.normal_y, a.normal_z, a.curvature};
    const float y[4] = {b.normal_x, b.normal_y, b.normal_z, b.curvature};
    ASSERT_EQ(std::memcmp(x, y, sizeof x), 0) << i;
  }
}

TEST(Interruption, ScopesNestAndTheEnclosingCheckComesBack) {
  EXPECT_FALSE(pollUntil(std::chrono::milliseconds(250)));  // no scope: nothing checked
  const InterruptionScope outer([] { return true; });
  {
    int inner_checks = 0;
    const InterruptionScope inner([&] {
      ++inner_checks;
      return false;
    });
    EXPECT_FALSE(pollUntil(std::chrono::milliseconds(350)));
    EXPECT_GE(inner_checks, 1);  // the innermost check is the one run
  }
  EXPECT_TRUE(pollUntil(std::chrono::seconds(30)));  // the outer one again: stops in ~0.1 s
}

}  // namespace
}  // namespace pcl_ddg
