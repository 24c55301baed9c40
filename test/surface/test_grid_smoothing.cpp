// Grid smoothing of organized clouds: the exact decay of a Fourier mode, holes, depth jumps,
// points kept on their rays, stability, and bad input.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>
#include <pcl/point_types.h>

#include <cmath>
#include <limits>

#include "pcl_ddg/surface/grid_smoothing.h"

namespace pcl_ddg {
namespace test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// An organized "depth image" seen from the origin: pixel (row, column) looks along a ray through
// (column - w/2, row - h/2, focal) and sees range(row, column) along it.
Eigen::Matrix3Xd imageFromRanges(const Eigen::MatrixXd& range) {
  const int height = static_cast<int>(range.rows()), width = static_cast<int>(range.cols());
  Eigen::Matrix3Xd points(3, width * height);
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) {
      const Eigen::Vector3d ray =
          Eigen::Vector3d(column - 0.5 * width, row - 0.5 * height, 2.0 * width).normalized();
      points.col(row * width + column) = range(row, column) * ray;
    }
  }
  return points;
}

Eigen::MatrixXd rangesOf(const Eigen::Matrix3Xd& points, int width, int height) {
  Eigen::MatrixXd range(height, width);
  for (int i = 0; i < width * height; ++i) range(i / width, i % width) = points.col(i).norm();
  return range;
}

// cos(pi k (column + 1/2) / w) cos(pi l (row + 1/2) / h): an eigenvector of the 5-point Laplacian
// with insulated borders, eigenvalue -4 sin^2(pi k / 2w) - 4 sin^2(pi l / 2h).
Eigen::MatrixXd fourierMode(int width, int height, int k, int l) {
  Eigen::MatrixXd mode(height, width);
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) {
      mode(row, column) =
          std::cos(kPi * k * (column + 0.5) / width) * std::cos(kPi * l * (row + 0.5) / height);
    }
  }
  return mode;
}

TEST(GridSmoothing, AFourierModeDecaysAtTheExactDiscreteRatePerStep) {
  const int width = 40, height = 30;
  for (const auto& [k, l] : {std::pair{1, 0}, std::pair{3, 2}, std::pair{17, 11}}) {
    const double eigenvalue = -4.0 * std::pow(std::sin(kPi * k / (2.0 * width)), 2) -
                              4.0 * std::pow(std::sin(kPi * l / (2.0 * height)), 2);
    const Eigen::MatrixXd mode = fourierMode(width, height, k, l);
    const Eigen::MatrixXd range = Eigen::MatrixXd::Constant(height, width, 10.0) + 0.01 * mode;
    for (const SmoothingScheme scheme : {SmoothingScheme::Explicit, SmoothingScheme::Implicit}) {
      GridSmoothingParameters p;
      p.scheme = scheme;
      p.time_step = scheme == SmoothingScheme::Explicit ? 0.2 : 3.0;
      p.iterations = 3;
      const double factor = scheme == SmoothingScheme::Explicit
                                ? 1.0 + p.time_step * eigenvalue
                                : 1.0 / (1.0 - p.time_step * eigenvalue);
      const Eigen::Matrix3Xd smoothed = smoothOrganizedPositions(
          imageFromRanges(range), width, height, Eigen::Vector3d::Zero(), p);
      const Eigen::MatrixXd expected =
          Eigen::MatrixXd::Constant(height, width, 10.0) + 0.01 * std::pow(factor, 3) * mode;
      const double error = (rangesOf(smoothed, width, height) - expected).cwiseAbs().maxCoeff();
      EXPECT_LT(error, 1e-12) << "mode (" << k << ", " << l << ")";
    }
  }
}

TEST(GridSmoothing, PointsStayOnTheirRaysAndAConstantRangeIsKept) {
  const int width = 12, height = 9;
  Eigen::MatrixXd range = Eigen::MatrixXd::Constant(height, width, 3.0);
  range += 0.05 * fourierMode(width, height, 2, 1);
  const Eigen::Vector3d origin(100.0, -50.0, 20.0);  // a sensor away from the origin
  const Eigen::Matrix3Xd points = imageFromRanges(range).colwise() + origin;
  GridSmoothingParameters p;
  p.time_step = 5.0;
  const Eigen::Matrix3Xd smoothed = smoothOrganizedPositions(points, width, height, origin, p);
  for (int i = 0; i < width * height; ++i) {
    const Eigen::Vector3d before = (points.col(i) - origin).normalized();
    const Eigen::Vector3d after = (smoothed.col(i) - origin).normalized();
    EXPECT_LT((before - after).norm(), 1e-12) << "pixel " << i;
  }
  const Eigen::Matrix3Xd flat = imageFromRanges(Eigen::MatrixXd::Constant(height, width, 3.0));
  EXPECT_LT((smoothOrganizedPositions(flat, width, height, Eigen::Vector3d::Zero(), p) - flat)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
}

TEST(GridSmoothing, HolesStayNaNAndDoNotSpread) {
  const int width = 20, height = 15;
  Eigen::MatrixXd range =
      Eigen::MatrixXd::Constant(height, width, 5.0) + 0.1 * fourierMode(width, height, 5, 4);
  Eigen::Matrix3Xd points = imageFromRanges(range);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const int hole : {0, 47, 48, 67, 150, 299}) points.col(hole).setConstant(nan);
  for (const SmoothingScheme scheme : {SmoothingScheme::Explicit, SmoothingScheme::Implicit}) {
    GridSmoothingParameters p;
    p.scheme = scheme;
    p.time_step = scheme == SmoothingScheme::Explicit ? 0.24 : 10.0;
    p.iterations = 20;
    GridSmoothingReport report;
    const Eigen::Matrix3Xd smoothed =
        smoothOrganizedPositions(points, width, height, Eigen::Vector3d::Zero(), p, &report);
    EXPECT_EQ(report.holes, 6);
    for (int i = 0; i < width * height; ++i) {
      EXPECT_EQ(smoothed.col(i).allFinite(), points.col(i).allFinite()) << "pixel " << i;
    }
    // Nothing was pulled towards zero by a hole: ranges stay within the input's.
    double lowest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < width * height; ++i) {
      if (smoothed.col(i).allFinite()) lowest = std::min(lowest, smoothed.col(i).norm());
    }
    EXPECT_GT(lowest, 4.9);
  }
}

TEST(GridSmoothing, NeighboursAcrossADepthJumpAreNotCoupled) {
  // A step: left half at range 2, right half at range 4, each with a little noise. Smoothing must
  // not blend the halves: the mean of each half is kept exactly (insulated on each side).
  const int width = 16, height = 10;
  Eigen::MatrixXd range(height, width);
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) {
      range(row, column) = (column < width / 2 ? 2.0 : 4.0) + 0.01 * ((row * 7 + column * 3) % 5);
    }
  }
  GridSmoothingParameters p;
  p.time_step = 50.0;
  p.max_depth_jump = 0.1;
  GridSmoothingReport report;
  const Eigen::MatrixXd smoothed =
      rangesOf(smoothOrganizedPositions(imageFromRanges(range), width, height,
                                        Eigen::Vector3d::Zero(), p, &report),
               width, height);
  EXPECT_EQ(report.cut_pairs, height);
  EXPECT_NEAR(smoothed.leftCols(width / 2).mean(), range.leftCols(width / 2).mean(), 1e-12);
  EXPECT_NEAR(smoothed.rightCols(width / 2).mean(), range.rightCols(width / 2).mean(), 1e-12);
  EXPECT_LT(smoothed.leftCols(width / 2).maxCoeff(), 2.05);
  EXPECT_GT(smoothed.rightCols(width / 2).minCoeff(), 3.95);
}

// The cut is relative to the nearer of the two ranges: |r_i - r_j| > f min(r_i, r_j). Ranges 1 and
// 1.05 differ by 0.05, which is above 0.0488 x 1 (cut) but below 0.0488 x 1.05 = 0.0512: a
// threshold relative to the farther range would couple them.
TEST(GridSmoothing, TheJumpIsRelativeToTheNearerRange) {
  const int width = 8, height = 4;
  Eigen::MatrixXd range(height, width);
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) range(row, column) = column < 4 ? 1.0 : 1.05;
  }
  for (const double f : {0.0488, 0.0512}) {
    GridSmoothingParameters p;
    p.max_depth_jump = f;
    GridSmoothingReport report;
    smoothOrganizedPositions(imageFromRanges(range), width, height, Eigen::Vector3d::Zero(), p,
                             &report);
    EXPECT_EQ(report.cut_pairs, f < 0.05 ? height : 0) << "max_depth_jump " << f;
  }
}

TEST(GridSmoothing, ExplicitAboveAQuarterIsUnstableImplicitIsNot) {
  const int width = 16, height = 16;
  const Eigen::MatrixXd range =
      Eigen::MatrixXd::Constant(height, width, 5.0) + 1e-3 * fourierMode(width, height, 15, 15);
  GridSmoothingParameters p;
  p.time_step = 0.3;  // the highest mode's factor is 1 - 0.3 * 7.9 = -1.4 per step
  p.iterations = 30;
  p.scheme = SmoothingScheme::Explicit;
  const Eigen::MatrixXd exploded = rangesOf(
      smoothOrganizedPositions(imageFromRanges(range), width, height, Eigen::Vector3d::Zero(), p),
      width, height);
  EXPECT_GT((exploded.array() - 5.0).abs().maxCoeff(), 1.0);
  p.scheme = SmoothingScheme::Implicit;
  const Eigen::MatrixXd damped = rangesOf(
      smoothOrganizedPositions(imageFromRanges(range), width, height, Eigen::Vector3d::Zero(), p),
      width, height);
  EXPECT_LT((damped.array() - 5.0).abs().maxCoeff(), 1e-12);
}

TEST(GridSmoothing, PCLCloudsAndBadInput) {
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  cloud.width = 4;
  cloud.height = 3;
  cloud.resize(12);
  for (int i = 0; i < 12; ++i) {
    cloud[i].x = 0.1f * (i % 4);
    cloud[i].y = 0.1f * (i / 4);
    cloud[i].z = 1.0f + 0.01f * (i % 3);
    cloud[i].r = static_cast<std::uint8_t>(i);
  }
  cloud.is_dense = true;
  pcl::PointCloud<pcl::PointXYZRGB> out;
  GridSmoothingParameters p;
  smoothOrganizedCloud(cloud, out, p);
  ASSERT_EQ(out.size(), 12u);
  EXPECT_EQ(out.width, 4u);
  EXPECT_EQ(out[5].r, 5) << "other fields copied";

  pcl::PointCloud<pcl::PointXYZRGB> unorganized = cloud;
  unorganized.width = 12;
  unorganized.height = 1;
  EXPECT_THROW(smoothOrganizedCloud(unorganized, out, p), pcl::BadArgumentException);
  p.time_step = 0.0;
  EXPECT_THROW(smoothOrganizedCloud(cloud, out, p), pcl::BadArgumentException);
  p.time_step = 1.0;
  p.iterations = 0;
  EXPECT_THROW(smoothOrganizedCloud(cloud, out, p), pcl::BadArgumentException);
  p.iterations = 1;
  EXPECT_THROW(smoothOrganizedPositions(Eigen::Matrix3Xd(3, 5), 4, 3, Eigen::Vector3d::Zero(), p),
               pcl::BadArgumentException);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
