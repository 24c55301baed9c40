// Topological versus Euclidean neighbourhoods: where a surface passes close to another sheet of
// itself, kd-tree neighbourhoods mix the sheets and the normals go wrong; mesh rings do not.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/features/neighbourhood_comparison.h"
#include "range_images.h"

namespace pcl_ddg {
namespace test {
namespace {

TEST(NeighbourhoodComparison, ThinTwoSheetSurfaceBFSRightKdTreeWrong) {
  const double h = 2.0 / 24;
  for (const LocalFitMethod method : {LocalFitMethod::PCA, LocalFitMethod::Quadric}) {
    // 1.5 h apart: measured kd-tree errors of 32 deg (pca) and 23 deg (quadric) on average.
    const double g = 1.5;
    const SurfaceSample s = makeTwoSheets(g * h);
    LocalFitOptions options;
    options.method = method;
    options.k = 16;
    const NeighbourhoodComparison c =
        compareNeighbourhoods(toCloud(s.points), topologyPtrOf(s), options);
    const AngleErrors bfs =
        angleErrors(normalsOf(c.topological.normals), s.normals, SignMode::Signed);
    const AngleErrors kd = angleErrors(normalsOf(c.kd_tree.normals), s.normals, SignMode::Unsigned);
    std::printf(
        "%s, sheets %.2fh apart: BFS error mean %.3g max %.3g deg; kd-tree error mean %.3g max "
        "%.3g deg; "
        "difference mean %.3g, over 30 deg %.1f%%, overlap %.3f\n",
        method == LocalFitMethod::PCA ? "pca" : "quadric", g, bfs.mean, bfs.max, kd.mean, kd.max,
        c.summary.mean, 100 * c.summary.share_over_30, c.summary.mean_overlap);
    EXPECT_LT(bfs.max, 1e-3);
    EXPECT_GT(kd.mean, 15.0);
    EXPECT_GT(c.summary.share_over_30, 0.1);
    EXPECT_LT(c.summary.mean_overlap, 0.6);
    EXPECT_EQ(c.summary.compared, s.points.cols());
  }
}

TEST(NeighbourhoodComparison, AgreeOnACleanWellSampledSurface) {
  const SurfaceSample torus = makeTorus({96, 0.0, 1});
  LocalFitOptions options;
  options.k = 16;
  const NeighbourhoodComparison c =
      compareNeighbourhoods(toCloud(torus.points), topologyPtrOf(torus), options);
  std::printf("torus: difference mean %.4f max %.4f deg, overlap %.3f\n", c.summary.mean,
              c.summary.max, c.summary.mean_overlap);
  EXPECT_LT(c.summary.mean, 2.0);
  EXPECT_EQ(c.summary.share_over_5, 0.0);
  EXPECT_GT(c.summary.mean_overlap, 0.6);
  EXPECT_LE(c.summary.median, c.summary.percentile95);
  EXPECT_LE(c.summary.percentile95, c.summary.max);
}

TEST(NeighbourhoodComparison, NeedsAMesh) {
  const SurfaceSample torus = makeTorus({16, 0.0, 1});
  EXPECT_THROW(compareNeighbourhoods(toCloud(torus.points), nullptr, {}),
               pcl::BadArgumentException);
}

TEST(NeighbourhoodComparison, PixelGridAgainstKdTreeAtADepthStep) {
  // A box 15 cm before a wall, seen by a pinhole camera: on the planes both neighbourhoods give
  // the exact normal; 2-4 pixels from the step the kd-tree reaches across it, the grid does not.
  const auto image = renderRangeImage(RangeScene::BoxOnWall, PinholeCamera{});
  LocalFitOptions options;
  options.k = 100;
  const NeighbourhoodComparison c = compareNeighbourhoods(image.cloud, nullptr, options);
  double far_worst = 0.0, near_mean = 0.0;
  int near = 0;
  for (std::size_t i = 0; i < image.normals.size(); ++i) {
    const double d = c.angle_difference[static_cast<Eigen::Index>(i)];
    if (!std::isfinite(d)) continue;
    if (image.pixels_from_step[i] > 8) far_worst = std::max(far_worst, d);
    if (image.pixels_from_step[i] >= 2 && image.pixels_from_step[i] <= 4) {
      near_mean += d;
      ++near;
    }
  }
  near_mean /= near;
  EXPECT_LT(far_worst, 0.01);
  EXPECT_GT(near_mean, 1.0);
  EXPECT_GT(c.summary.compared, 15000);
  // Without a mesh or a pixel grid there is nothing topological to compare.
  pcl::PointCloud<pcl::PointXYZ>::Ptr flat(new pcl::PointCloud<pcl::PointXYZ>(*image.cloud));
  flat->width = static_cast<std::uint32_t>(flat->size());
  flat->height = 1;
  EXPECT_THROW(compareNeighbourhoods(flat, nullptr, options), pcl::BadArgumentException);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
