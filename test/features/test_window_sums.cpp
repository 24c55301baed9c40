// The window sums behind the organized PCA normals, against the two-pass covariance of the finite
// points of each window: the count exactly and the covariance to 1e-9 relative, on a Kinect frame
// (holes everywhere) and on a noisy sphere 1e5 from the origin, for several window sizes, with
// tiles that do not divide the image.
#include <gtest/gtest.h>
#include <pcl/common/point_tests.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <vector>

#include "features/window_sums.h"
#include "range_images.h"
#include "test_data.h"

namespace pcl_ddg {
namespace {

using detail::WindowSums;

/** The covariance (divided by the count) of the finite points of the window, in two passes over
 *  the window. Plain arithmetic, no copy: the brute force runs for every pixel, under the
 *  sanitizers too, where Eigen's small expressions are not inlined. */
Eigen::Matrix3d twoPassCovariance(const pcl::PointCloud<pcl::PointXYZ>& cloud, int x, int y,
                                  int radius, int& count) {
  const int u0 = std::max(0, x - radius), u1 = std::min<int>(cloud.width - 1, x + radius);
  const int v0 = std::max(0, y - radius), v1 = std::min<int>(cloud.height - 1, y + radius);
  const auto forEachPoint = [&](const auto& visit) {
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const pcl::PointXYZ& p = cloud.at(u, v);
        if (pcl::isXYZFinite(p)) visit(double{p.x}, double{p.y}, double{p.z});
      }
    }
  };
  count = 0;
  double mean[3] = {0.0, 0.0, 0.0};
  forEachPoint([&](double px, double py, double pz) {
    mean[0] += px;
    mean[1] += py;
    mean[2] += pz;
    ++count;
  });
  for (double& m : mean) m /= std::max(count, 1);
  double c[3][3] = {};
  forEachPoint([&](double px, double py, double pz) {
    const double d[3] = {px - mean[0], py - mean[1], pz - mean[2]};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) c[r][k] += d[r] * d[k];
  });
  Eigen::Matrix3d covariance;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) covariance(r, k) = c[r][k] / std::max(count, 1);
  return covariance;
}

void expectSumsEqualTwoPass(const pcl::PointCloud<pcl::PointXYZ>& cloud, int radius) {
  SCOPED_TRACE(radius);
  std::vector<std::uint8_t> finite(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) finite[i] = pcl::isXYZFinite(cloud[i]);
  WindowSums sums(cloud, nullptr, finite, radius);
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  constexpr int kTileHeight = 37;  // divides neither 480 nor the 64-pixel tile width
  int compared = 0;
  double worst = 0.0;
  for (int y0 = 0; y0 < height; y0 += kTileHeight) {
    for (int x0 = 0; x0 < width; x0 += WindowSums::kTileWidth) {
      const int x1 = std::min(width, x0 + WindowSums::kTileWidth);
      const int y1 = std::min(height, y0 + kTileHeight);
      sums.startTile(x0, y0, x1, y1);
      for (int y = y0; y < y1; ++y) {
        const double* s = sums.rowSums(y);
        const auto at = [&](int channel, int j) { return s[channel * WindowSums::kTileWidth + j]; };
        for (int j = 0; j < x1 - x0; ++j) {
          int count = 0;
          const Eigen::Matrix3d truth = twoPassCovariance(cloud, x0 + j, y, radius, count);
          ASSERT_EQ(at(WindowSums::kCount, j), count) << x0 + j << " " << y;
          if (count < 3) continue;
          const Eigen::Vector3d mean =
              Eigen::Vector3d(at(WindowSums::kX, j), at(WindowSums::kY, j), at(WindowSums::kZ, j)) /
              count;
          Eigen::Matrix3d covariance;
          covariance << at(WindowSums::kXX, j), at(WindowSums::kXY, j), at(WindowSums::kXZ, j),
              at(WindowSums::kXY, j), at(WindowSums::kYY, j), at(WindowSums::kYZ, j),
              at(WindowSums::kXZ, j), at(WindowSums::kYZ, j), at(WindowSums::kZZ, j);
          covariance = covariance / count - mean * mean.transpose();
          if (truth.norm() == 0.0) continue;
          worst = std::max(worst, (covariance - truth).norm() / truth.norm());
          ++compared;
        }
      }
    }
  }
  std::printf("radius %d: %d windows, worst relative covariance error %.3g\n", radius, compared,
              worst);
  EXPECT_GT(compared, static_cast<int>(cloud.size()) / 3);
  EXPECT_LT(worst, 1e-9);
}

TEST(WindowSums, EqualTwoPassCovariancesOnAKinectFrame) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(test::sharedData("clouds/office1.pcd"), cloud), 0);
  for (const int radius : {1, 3, 6}) expectSumsEqualTwoPass(cloud, radius);
}

TEST(WindowSums, EqualTwoPassCovariancesFarFromTheOrigin) {
  const auto image = test::renderRangeImage(test::RangeScene::Sphere, test::PinholeCamera{}, 2e-3,
                                            7, {1e5, -1e5, 1e5});
  for (const int radius : {2, 3}) expectSumsEqualTwoPass(*image.cloud, radius);
}

}  // namespace
}  // namespace pcl_ddg
