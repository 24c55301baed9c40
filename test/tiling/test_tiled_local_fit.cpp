// Tiles give the whole-cloud result bit for bit: on every shared cloud with tiles forced small, for
// PCA, quadric and robust (its wider planes included), k nearest and radius; the halo grows where a
// tile's points look far (a dense cluster in a sparse cloud); the plan gives every point one tile.
#include <gtest/gtest.h>

#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "data_catalogue.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/tiling/tiled_local_fit.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr loadCloud(const std::string& file) {
  auto cloud = std::make_shared<Cloud>();
  pcl::fromPCLPointCloud2(loadMesh(sharedData(file)).cloud, *cloud);
  return cloud;
}

// The values of a result, as bits (NaN included; the structs' padding left out).
std::vector<float> valuesOf(const pcl::Normal& n) {
  return {n.normal_x, n.normal_y, n.normal_z, n.curvature};
}
std::vector<float> valuesOf(const pcl::PrincipalCurvatures& c) {
  return {c.principal_curvature_x, c.principal_curvature_y, c.principal_curvature_z, c.pc1, c.pc2};
}

template <typename Point>
void expectSameBits(const pcl::PointCloud<Point>& a, const pcl::PointCloud<Point>& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.is_dense, b.is_dense);
  std::size_t different = 0, first = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::vector<float> x = valuesOf(a[i]), y = valuesOf(b[i]);
    if (std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0) continue;
    if (different++ == 0) first = i;
  }
  EXPECT_EQ(different, 0u) << "first at point " << first;
}

void expectSameBits(const std::vector<float>& a, const std::vector<float>& b) {
  ASSERT_EQ(a.size(), b.size());
  if (a.empty()) return;  // (memcmp must not be given an empty vector's null data)
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
}

/** The whole cloud's fit, which the tiled one is checked against. */
LocalFitResult expectTiledEqualsWhole(const LocalCloud& cloud, const LocalFitOptions& options,
                                      std::int64_t tile_points, TilingReport* report = nullptr) {
  const LocalFitResult whole = fitLocalSurfaces(cloud, nullptr, options);
  TilingOptions tiling;
  tiling.max_points_per_tile = tile_points;
  TilingReport local;
  const LocalFitResult tiled = fitLocalSurfacesTiled(cloud, options, tiling, &local);
  EXPECT_GT(local.tiles, 1u);
  expectSameBits(tiled.normals, whole.normals);
  expectSameBits(tiled.curvatures, whole.curvatures);
  EXPECT_EQ(tiled.failed_points, whole.failed_points);
  EXPECT_EQ(tiled.fallback_points, whole.fallback_points);
  expectSameBits(tiled.scales, whole.scales);
  expectSameBits(tiled.confidences, whole.confidences);
  if (report) *report = local;
  return whole;
}

TEST(TiledLocalFit, PCAOnEverySharedCloudEqualsTheWholeCloudBitForBit) {
  std::vector<std::string> files = {"range/bun000.ply"};
  for (const SharedCloud& cloud : sharedClouds()) files.push_back(cloud.path);
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    const Cloud::Ptr cloud = loadCloud(file);
    LocalFitOptions options;
    options.k = 16;
    options.viewpoint = Eigen::Vector3d(0.1, 0.2, 0.3);
    TilingReport report;
    // About twenty tiles, and at most a few thousand points in each.
    expectTiledEqualsWhole(
        cloud, options, std::max<std::int64_t>(50, static_cast<std::int64_t>(cloud->size()) / 20),
        &report);
    std::printf(
        "%s: %zu points, %zu tiles, %lld halo growths, %lld far points, at most %lld "
        "gathered\n",
        file.c_str(), cloud->size(), report.tiles, static_cast<long long>(report.halo_growths),
        static_cast<long long>(report.far_points), static_cast<long long>(report.largest_gather));
  }
}

TEST(TiledLocalFit, QuadricAndRadiusSearchesToo) {
  LocalFitOptions quadric;
  quadric.method = LocalFitMethod::Quadric;
  quadric.k = 20;
  expectTiledEqualsWhole(loadCloud("clouds/milk.pcd"), quadric, 1000);
  // Half of the room scan is exact duplicates: ties everywhere, decided by index.
  LocalFitOptions radius;
  radius.radius = 0.078;
  radius.max_neighbours = 64;
  expectTiledEqualsWhole(loadCloud("clouds/tutorials_room_scan1.pcd"), radius, 8000);
  radius.max_neighbours = 0;
  radius.radius = 0.03;
  expectTiledEqualsWhole(loadCloud("clouds/bun0.pcd"), radius, 40);
}

// Points of which at least one widened (a scale above the k searched).
std::size_t widened(const LocalFitResult& fit, int k) {
  return static_cast<std::size_t>(
      std::count_if(fit.scales.begin(), fit.scales.end(), [&](float s) { return s > k; }));
}

// n points over [0, width] x [0, depth] at survey offsets, at height(x) plus Gaussian noise of
// 0.01: a noisy surface whose robust planes widen.
template <typename Height>
Eigen::Matrix3Xd noisySurveyField(unsigned seed, int n, double width, double depth, Height height) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  Eigen::Matrix3Xd world(3, n);
  for (int i = 0; i < n; ++i) {
    const double x = width * unit(random), y = depth * unit(random);
    world.col(i) = Eigen::Vector3d(512345.25 + x, 4212345.5 + y, height(x) + noise(random));
  }
  return world;
}

TEST(TiledLocalFit, RobustWithItsWiderPlanesEqualsTheWholeCloudBitForBit) {
  // A noisy roof (two planes meeting at a ridge, noise 1 % of the spacing's tenfold) at survey
  // coordinates: the wider planes widen on the faces and stop at the ridge, and read rows up to
  // twelve steps away, far past the k nearest.
  const int n = 30000;
  const LocalCloud roof = makeLocalCloud(
      noisySurveyField(7, n, 10.0, 10.0, [](double x) { return 120.0 + 0.4 * std::abs(x - 5.0); }));
  ASSERT_TRUE(roof.positions);
  LocalFitOptions robust;
  robust.method = LocalFitMethod::Robust;
  robust.k = 96;
  robust.viewpoint = Eigen::Vector3d(512350.0, 4212350.0, 200.0);
  TilingReport report;
  const LocalFitResult whole = expectTiledEqualsWhole(roof, robust, 3000, &report);
  EXPECT_GT(widened(whole, robust.k), static_cast<std::size_t>(n) / 2);
  EXPECT_GT(report.widest_halo, 1.0);  // the rows' reach, several times the 96 nearest's radius
  std::printf(
      "robust roof: %zu tiles, %lld halo growths, %lld far points, widest halo %.3f, "
      "%lld gathered at most\n",
      report.tiles, static_cast<long long>(report.halo_growths),
      static_cast<long long>(report.far_points), report.widest_halo,
      static_cast<long long>(report.largest_gather));

  // A real scan in float, with its duplicates and sparse rim; and a radius, where robust does
  // not widen.
  expectTiledEqualsWhole(loadCloud("clouds/milk.pcd"), robust, 1500, &report);
  robust.radius = 0.01;
  robust.max_neighbours = 64;
  expectTiledEqualsWhole(loadCloud("clouds/milk.pcd"), robust, 1500);
}

TEST(TiledLocalFit, RobustFitsHoldNoMorePointsThanATileOwnsWhereTheHaloAllows) {
  // A noisy strip 40 long and 2.5 wide at survey coordinates, cut into tiles of at most 15,000
  // points: the wider planes' halo (about 4) gathers 18,000 about the largest; fitted in
  // parts (halves of a tile, each with its own halo), no fit holds more than a tile's points, and
  // the bits are the whole cloud's.
  const int n = 30000;
  const Eigen::Matrix3Xd world =
      noisySurveyField(5, n, 40.0, 2.5, [](double x) { return 80.0 + 0.1 * x; });
  LocalFitOptions robust;
  robust.method = LocalFitMethod::Robust;
  robust.k = 96;
  robust.viewpoint = Eigen::Vector3d(512365.0, 4212346.0, 200.0);
  TilingReport report;
  const LocalFitResult whole =
      expectTiledEqualsWhole(makeLocalCloud(world), robust, n / 2, &report);
  EXPECT_GT(widened(whole, robust.k), static_cast<std::size_t>(n) / 2);
  EXPECT_GE(report.tiles, 2u);
  EXPECT_GT(report.widest_halo, 2.0);
  EXPECT_LE(report.largest_gather, n / 2);
  std::printf(
      "robust strip: widest halo %.3f, %lld halo growths, %lld far points, %lld fitted "
      "at most\n",
      report.widest_halo, static_cast<long long>(report.halo_growths),
      static_cast<long long>(report.far_points), static_cast<long long>(report.largest_gather));
}

TEST(TiledLocalFit, TheHaloGrowsAroundADenseClusterInASparseCloud) {
  // 20,000 points in a ball of radius 0.01 at the centre of 2,000 points spread over a unit cube:
  // the tiles around the cluster are tiny in space, and the sparse points in them find their k
  // nearest far outside.
  auto cloud = std::make_shared<Cloud>();
  std::mt19937 random(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> cluster(0.0f, 0.004f);
  for (int i = 0; i < 2000; ++i) cloud->push_back({unit(random), unit(random), unit(random)});
  for (int i = 0; i < 20000; ++i)
    cloud->push_back({0.5f + cluster(random), 0.5f + cluster(random), 0.5f + cluster(random)});
  LocalFitOptions options;
  options.k = 24;
  TilingReport report;
  expectTiledEqualsWhole(cloud, options, 500, &report);
  EXPECT_GT(report.halo_growths + report.far_points, 0);
  std::printf("dense cluster: %zu tiles, %lld halo growths, %lld far points, widest halo %.3f\n",
              report.tiles, static_cast<long long>(report.halo_growths),
              static_cast<long long>(report.far_points), report.widest_halo);
}

TEST(TilePlan, EveryPointHasOneTileAndTilesKeepTheirLimitWhereCellsAllow) {
  const Cloud::Ptr cloud = loadCloud("clouds/rs1.pcd");
  Eigen::AlignedBox3d bounds;
  for (const auto& p : *cloud) bounds.extend(p.getVector3fMap().cast<double>());
  PointHistogram histogram(bounds, 32);
  for (const auto& p : *cloud) histogram.add(p.getVector3fMap().cast<double>());
  const TilePlan plan = planTiles(histogram, 10000);
  std::vector<std::int64_t> counted(plan.tiles.size(), 0);
  for (const auto& p : *cloud) {
    const int t = plan.tileOf(p.getVector3fMap().cast<double>());
    ASSERT_GE(t, 0);
    ++counted[t];
  }
  std::int64_t total = 0;
  for (std::size_t t = 0; t < plan.tiles.size(); ++t) {
    EXPECT_EQ(counted[t], plan.tiles[t].points);
    const bool single_cell = (plan.tiles[t].end_cell - plan.tiles[t].first_cell).maxCoeff() == 1;
    if (!single_cell) EXPECT_LE(plan.tiles[t].points, 10000);
    total += counted[t];
  }
  EXPECT_EQ(total, static_cast<std::int64_t>(cloud->size()));
  EXPECT_GT(plan.tiles.size(), 29u);  // 290k points
  EXPECT_NE(plan.toJson().find("\"resolution\": 32"), std::string::npos);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
