// Survey coordinates (local_cloud.h): a cloud millions of units from the origin is searched in
// floats about its local origin and fitted in its exact doubles, so that its normals and
// curvatures are those of the same cloud at the origin. The clouds are snapped to multiples of
// 2^-16, so that moving them by (5e5, 5e6, 200) is exact in double: any difference is then the
// library's, not the test's.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <pcl/search/kdtree.h>

#include "estimator_support.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/mesh/local_cloud.h"
#include "pcl_ddg/tiling/tiled_local_fit.h"

namespace pcl_ddg {
namespace test {
namespace {

const Eigen::Vector3d kSurveyOffset(5e5, 5e6, 200.0);

double snapped(double v) {
  return std::round(v * 65536.0) / 65536.0;
}

// A sphere of radius 20 (uniform on it) beside a height field z = 2 sin(x / 7) cos(y / 5) over a
// jittered 100 x 100 grid of spacing 1: both with exact normals, snapped.
struct Scene {
  Eigen::Matrix3Xd points, normals;
};

Scene makeScene(int sphere_points = 12000) {
  std::mt19937 random(7);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  const int grid = 100;
  Scene s;
  s.points.resize(3, sphere_points + grid * grid);
  s.normals.resize(3, s.points.cols());
  const Eigen::Vector3d centre(150.0, 0.0, 0.0);
  for (int i = 0; i < sphere_points; ++i) {
    Eigen::Vector3d d(gauss(random), gauss(random), gauss(random));
    d.normalize();
    s.points.col(i) = centre + 20.0 * d;
    s.normals.col(i) = d;
  }
  for (int r = 0; r < grid; ++r) {
    for (int c = 0; c < grid; ++c) {
      const int i = sphere_points + r * grid + c;
      const double x = c - 50.0 + jitter(random), y = r - 50.0 + jitter(random);
      s.points.col(i) << x, y, 2.0 * std::sin(x / 7.0) * std::cos(y / 5.0);
      const double zx = 2.0 / 7.0 * std::cos(x / 7.0) * std::cos(y / 5.0);
      const double zy = -2.0 / 5.0 * std::sin(x / 7.0) * std::sin(y / 5.0);
      s.normals.col(i) = Eigen::Vector3d(-zx, -zy, 1.0).normalized();
    }
  }
  s.points = s.points.unaryExpr(&snapped);
  return s;
}

double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

// Points whose k-th and (k+1)-th nearest distances differ by less than the float searches can
// tell apart: each frame's floats round a coordinate by up to 2.4e-7 of the cloud's side
// (local_cloud.h), a distance by up to sqrt(3) times that, so two frames may order such a pair
// either way and fit another k-th neighbour. Found among the k + 8 nearest of a float search,
// measured in double.
std::vector<bool> nearTies(const Eigen::Matrix3Xd& points, int k) {
  const double side = (points.rowwise().maxCoeff() - points.rowwise().minCoeff()).maxCoeff();
  const double tolerance = 4.0 * std::sqrt(3.0) * 2.4e-7 * side;
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(toCloud(points));
  std::vector<bool> tied(points.cols(), false);
  pcl::Indices found;
  std::vector<float> squared;
  std::vector<double> distances;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const int n = tree.nearestKSearch(static_cast<pcl::index_t>(i), k + 8, found, squared);
    distances.clear();
    for (int j = 0; j < n; ++j) distances.push_back((points.col(found[j]) - points.col(i)).norm());
    std::sort(distances.begin(), distances.end());
    tied[i] = n > k && distances[k] - distances[k - 1] <= tolerance;
  }
  return tied;
}

TEST(LocalOrigin, StaysAtZeroAlongAxesTheDataSpansAroundTheOrigin) {
  Eigen::Matrix3Xd p(3, 2);
  p << -1.0, 3.0, 0.5, 1.5, 2.0, 2.5;
  // x spans 0, y comes within its side (1) of 0; z (2 to 2.5, a side of 0.5) lies 4 sides away:
  // its centre 2.25 rounds to a multiple of 0.5.
  EXPECT_EQ(localOrigin(p), Eigen::Vector3d(0.0, 0.0, 2.5));
  EXPECT_EQ(localOrigin(Eigen::Matrix3Xd(3, 0)), Eigen::Vector3d::Zero());
  Eigen::Matrix3Xd nan = Eigen::Matrix3Xd::Constant(3, 2, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(localOrigin(nan), Eigen::Vector3d::Zero());
}

TEST(LocalOrigin, IsAMultipleOfThePowerOfTwoAboveTheExtentNearTheCentre) {
  Eigen::Matrix3Xd p(3, 3);
  p.col(0) = kSurveyOffset;
  p.col(1) = kSurveyOffset + Eigen::Vector3d(300.0, 200.0, 50.0);
  p.col(2) = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const Eigen::Vector3d o = localOrigin(p);
  // The smallest powers of two not below the sides 300, 200 and 50.
  EXPECT_EQ(std::fmod(o.x(), 512.0), 0.0);
  EXPECT_EQ(std::fmod(o.y(), 256.0), 0.0);
  EXPECT_EQ(o.z(), 256.0);  // 225 rounded to a multiple of 64
  EXPECT_LE(std::abs(o.x() - (kSurveyOffset.x() + 150.0)), 256.0);
  EXPECT_LE(std::abs(o.y() - (kSurveyOffset.y() + 100.0)), 128.0);
  // Longitude and latitude (a side of 0.01 degree) beside heights in metres (a side of 100): each
  // axis is centred on its own scale, so the floats resolve the degrees too.
  Eigen::Matrix3Xd geographic(3, 2);
  geographic << -123.075, -123.065, 44.05, 44.06, 120.0, 220.0;
  const Eigen::Vector3d g = localOrigin(geographic);
  EXPECT_LE(std::abs(g.x() + 123.07), 1.0 / 128);
  EXPECT_LE(std::abs(g.y() - 44.055), 1.0 / 128);
  EXPECT_EQ(g.z(), 0.0);  // 120 lies within 128 of 0
  // One place: the origin is the place.
  Eigen::Matrix3Xd one(3, 1);
  one.col(0) = kSurveyOffset;
  EXPECT_EQ(localOrigin(one), kSurveyOffset);
}

TEST(LocalCloud, PositionsAreTheExactDifferencesAndTheFloatsRoundByAFractionOfTheExtent) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const double side : {1e-3, 0.7, 123.0, 4096.0, 3e5}) {
    Eigen::Matrix3Xd p(3, 2000);
    const Eigen::Vector3d sides(side, 0.01 * side, side);  // one axis a hundred times thinner
    for (Eigen::Index i = 0; i < p.cols(); ++i)
      for (int d = 0; d < 3; ++d) p(d, i) = (d == 1 ? 4.3e6 : 6.8e5) + sides[d] * u(random);
    const LocalCloud local = makeLocalCloud(p);
    Eigen::Vector3d worst = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < p.cols(); ++i) {
      for (int d = 0; d < 3; ++d) {
        const double fitted = local.positions ? (*local.positions)(d, i)
                                              : static_cast<double>((*local.points)[i].data[d]);
        const long double exact =
            static_cast<long double>(p(d, i)) - static_cast<long double>(local.origin[d]);
        EXPECT_EQ(static_cast<long double>(fitted), exact);
        EXPECT_EQ(fitted + local.origin[d], p(d, i));
        worst[d] =
            std::max(worst[d], std::abs(static_cast<double>((*local.points)[i].data[d]) - fitted));
      }
    }
    for (int d = 0; d < 3; ++d) EXPECT_LE(worst[d], 2.4e-7 * sides[d]) << "side " << sides[d];
  }
}

// A float file's coordinates (or any the floats hold exactly about the origin) need no doubles:
// the fits read the floats, as they read a PCL user's float cloud.
TEST(LocalCloud, KeepsTheDoublesOnlyWhereTheFloatsRoundThem) {
  Eigen::Matrix3Xd p(3, 3);
  p << 0.5, 1.25, -3.0, 1e5, 2.0, 0.125, 7.0, 8.0, 9.0;
  EXPECT_FALSE(makeLocalCloud(p).positions);
  p(0, 0) = 0.1;  // not a float
  const LocalCloud local = makeLocalCloud(p);
  ASSERT_TRUE(local.positions);
  EXPECT_EQ((*local.positions)(0, 0) + local.origin.x(), 0.1);
}

LocalFitOptions kdTree(LocalFitMethod method, int k) {
  LocalFitOptions options;
  options.method = method;
  options.k = k;
  options.orientation = NormalOrientation::Up;
  return options;
}

struct Moved {
  double max_angle = 0.0;     ///< radians, over the points not near a tie
  double max_relative = 0.0;  ///< principal curvatures, relative, over the same
  int differing = 0;          ///< points beyond 1e-9 (all near ties)
  int near_ties = 0;
};

Moved compareMoved(const Scene& scene, LocalFitMethod method, int k) {
  const Eigen::Matrix3Xd moved = scene.points.colwise() + kSurveyOffset;
  for (Eigen::Index i = 0; i < moved.cols(); ++i)  // the move is exact
    EXPECT_EQ(moved.col(i) - kSurveyOffset, scene.points.col(i));
  const LocalFitResult here =
      fitLocalSurfaces(makeLocalCloud(scene.points), nullptr, kdTree(method, k));
  const LocalFitResult there = fitLocalSurfaces(makeLocalCloud(moved), nullptr, kdTree(method, k));
  const std::vector<bool> tied = nearTies(scene.points, k);
  const Eigen::Matrix3Xd a = normalsOf(here.normals), b = normalsOf(there.normals);
  Moved m;
  for (Eigen::Index i = 0; i < a.cols(); ++i) {
    EXPECT_TRUE(a.col(i).allFinite() && b.col(i).allFinite()) << i;
    double relative = 0.0;
    if (method == LocalFitMethod::Quadric) {
      const auto& p = here.curvatures[i];
      const auto& q = there.curvatures[i];
      relative = std::max(std::abs(p.pc1 - q.pc1) / std::max(std::abs(p.pc1), 1e-3f),
                          std::abs(p.pc2 - q.pc2) / std::max(std::abs(p.pc2), 1e-3f));
    }
    const double difference = angle(a.col(i), b.col(i));
    m.near_ties += tied[i];
    if (difference > 1e-9 || relative > 1e-9) ++m.differing;
    if (tied[i]) continue;
    m.max_angle = std::max(m.max_angle, difference);
    m.max_relative = std::max(m.max_relative, relative);
  }
  return m;
}

// The normals' float output rounds at 6e-8: 1e-9 rad means the fits were the same.
TEST(LocalFit, PCANormalsDoNotDependOnWhereTheCloudSits) {
  const Moved m = compareMoved(makeScene(), LocalFitMethod::PCA, 16);
  EXPECT_LE(m.max_angle, 1e-9);
  EXPECT_LE(m.differing, m.near_ties);
  EXPECT_LE(m.near_ties, 220);  // 1 % of 22,000 points
}

TEST(LocalFit, QuadricNormalsAndCurvaturesDoNotDependOnWhereTheCloudSits) {
  const Moved m = compareMoved(makeScene(), LocalFitMethod::Quadric, 20);
  EXPECT_LE(m.max_angle, 1e-9);
  EXPECT_LE(m.max_relative, 1e-9);
  EXPECT_LE(m.differing, m.near_ties);
}

TEST(LocalFit, RobustNormalsDoNotDependOnWhereTheCloudSits) {
  const Moved m = compareMoved(makeScene(4000), LocalFitMethod::Robust, 48);
  EXPECT_LE(m.max_angle, 1e-9);
}

// Against an independent fit: each sampled point's k nearest found by brute force in long double
// on the world coordinates, their covariance about their mean, Eigen's eigenvector of the smallest
// eigenvalue. Also against the exact normal, at the accuracy PCA has on this sampling.
TEST(LocalFit, SurveyCloudNormalsEqualAnIndependentDoublePCA) {
  const Scene scene = makeScene();
  const Eigen::Matrix3Xd world = scene.points.colwise() + kSurveyOffset;
  const int k = 16;
  const LocalFitResult fit =
      fitLocalSurfaces(makeLocalCloud(world), nullptr, kdTree(LocalFitMethod::PCA, k));
  const Eigen::Matrix3Xd ours = normalsOf(fit.normals);
  double worst = 0.0, worst_truth = 0.0;
  for (Eigen::Index i = 0; i < world.cols(); i += 97) {
    worst = std::max(worst, angle(ours.col(i), bruteForcePcaNormal(world, i, k)));
    worst_truth = std::max(worst_truth, angle(ours.col(i), scene.normals.col(i)));
  }
  EXPECT_LE(worst, 1e-6);
  EXPECT_LE(worst_truth, 3.0 * M_PI / 180.0);  // PCA's own error on this sampling
}

// Far from the origin the floats of the world coordinates step by 0.5 at 5e6: fitted as floats,
// the height field's normals would be degrees off. This is what the local origin cures (and what
// a float cloud given as such keeps: its floats are its coordinates).
TEST(LocalFit, TheWorldsFloatsWouldHaveBeenWrong) {
  const Scene scene = makeScene(0);  // scaled to a spacing of 0.2 below (its normals unchanged)
  const Eigen::Matrix3Xd world = (0.2 * scene.points).colwise() + kSurveyOffset;
  const LocalFitResult rounded =
      fitLocalSurfaces(toCloud(world), nullptr, kdTree(LocalFitMethod::PCA, 16));
  const LocalFitResult exact =
      fitLocalSurfaces(makeLocalCloud(world), nullptr, kdTree(LocalFitMethod::PCA, 16));
  const AngleErrors bad =
      angleErrors(normalsOf(rounded.normals), scene.normals, SignMode::Unsigned);
  const AngleErrors good = angleErrors(normalsOf(exact.normals), scene.normals, SignMode::Unsigned);
  EXPECT_GT(bad.mean, 3.0) << bad.mean;    // 3.9 degrees here
  EXPECT_LT(good.mean, 1.0) << good.mean;  // PCA's own error on this sampling
}

TEST(LocalFit, TilesOfASurveyCloudGiveTheWholeCloudsBits) {
  const Scene scene = makeScene(6000);
  const LocalCloud local = makeLocalCloud(scene.points.colwise() + kSurveyOffset);
  for (const LocalFitMethod method : {LocalFitMethod::PCA, LocalFitMethod::Quadric}) {
    const LocalFitOptions options = kdTree(method, 16);
    const LocalFitResult whole = fitLocalSurfaces(local, nullptr, options);
    TilingOptions tiling;
    tiling.max_points_per_tile = 2000;
    TilingReport report;
    const LocalFitResult tiled = fitLocalSurfacesTiled(local, options, tiling, &report);
    EXPECT_GT(report.tiles, 4u);
    ASSERT_EQ(tiled.normals.size(), whole.normals.size());
    for (std::size_t i = 0; i < whole.normals.size(); ++i) {
      // The values' bits (pcl::Normal's padding is not written and may differ).
      const pcl::Normal &a = tiled.normals[i], &b = whole.normals[i];
      const float x[4] = {a.normal_x, a.normal_y, a.normal_z, a.curvature};
      const float y[4] = {b.normal_x, b.normal_y, b.normal_z, b.curvature};
      EXPECT_EQ(std::memcmp(x, y, sizeof x), 0) << i;
      if (method == LocalFitMethod::Quadric)
        EXPECT_EQ(tiled.curvatures[i].pc1, whole.curvatures[i].pc1) << i;
    }
  }
}

// Sliced, a fit hands every point over once, in order, with the bits of the whole cloud's fit:
// PCA, quadric and robust (its scales and confidences too), with points left out (NaN) counted.
TEST(LocalFit, SlicesGiveTheWholeCloudsBitsAndCounts) {
  const Scene scene = makeScene(3000);
  Eigen::Matrix3Xd world = scene.points.colwise() + kSurveyOffset;
  std::int64_t left_out = 0;
  for (Eigen::Index i = 5; i < world.cols(); i += 401, ++left_out) world.col(i).setConstant(NAN);
  for (const bool dense : {true, false}) {
    const LocalCloud local =
        makeLocalCloud(dense ? Eigen::Matrix3Xd(scene.points.colwise() + kSurveyOffset) : world);
    for (const LocalFitMethod method :
         {LocalFitMethod::PCA, LocalFitMethod::Quadric, LocalFitMethod::Robust}) {
      const LocalFitOptions options = kdTree(method, method == LocalFitMethod::Robust ? 48 : 16);
      const LocalFitResult whole = fitLocalSurfaces(local, nullptr, options);
      std::size_t next = 0, slices = 0;
      const LocalFitResult counts = fitLocalSurfacesInSlices(
          local, nullptr, options, 700, [&](std::size_t first, LocalFitResult& slice) {
            ASSERT_EQ(first, next);
            ++slices;
            for (std::size_t j = 0; j < slice.normals.size(); ++j) {
              const pcl::Normal &a = slice.normals[j], &b = whole.normals[first + j];
              const float x[4] = {a.normal_x, a.normal_y, a.normal_z, a.curvature};
              const float y[4] = {b.normal_x, b.normal_y, b.normal_z, b.curvature};
              ASSERT_EQ(std::memcmp(x, y, sizeof x), 0) << first + j;
              if (method == LocalFitMethod::Quadric)
                ASSERT_EQ(std::memcmp(&slice.curvatures[j], &whole.curvatures[first + j],
                                      sizeof(pcl::PrincipalCurvatures)),
                          0);
              if (method == LocalFitMethod::Robust) {
                ASSERT_EQ(std::memcmp(&slice.scales[j], &whole.scales[first + j], 4), 0);
                ASSERT_EQ(std::memcmp(&slice.confidences[j], &whole.confidences[first + j], 4), 0);
              }
            }
            next += slice.normals.size();
          });
      EXPECT_EQ(next, whole.normals.size());
      // Robust's wider planes span the whole cloud: one slice.
      EXPECT_EQ(slices, method == LocalFitMethod::Robust ? 1 : (whole.normals.size() + 699) / 700);
      EXPECT_EQ(counts.failed_points, whole.failed_points);
      EXPECT_EQ(counts.fallback_points, whole.fallback_points);
      EXPECT_EQ(whole.failed_points, dense ? 0 : left_out);
      EXPECT_TRUE(counts.normals.empty());
    }
  }
  // A spanning tree orients the normals together: one slice.
  LocalFitOptions tree = kdTree(LocalFitMethod::PCA, 16);
  tree.orientation = NormalOrientation::SpanningTree;
  int slices = 0;
  fitLocalSurfacesInSlices(
      makeLocalCloud(world), nullptr, tree, 700, [&](std::size_t first, LocalFitResult& slice) {
        EXPECT_EQ(first, 0u);
        EXPECT_EQ(slice.normals.size(), static_cast<std::size_t>(world.cols()));
        ++slices;
      });
  EXPECT_EQ(slices, 1);
}

// A caller's own positions shifted in place (what the tools do, instead of a second copy) make
// the cloud makeLocalCloud makes, and shift back to the coordinates they were, bit for bit.
TEST(LocalCloud, PositionsShiftedInPlaceAreMakeLocalCloudsAndShiftBackExactly) {
  const Scene scene = makeScene(2000);
  const Eigen::Matrix3Xd world = (0.37 * scene.points).colwise() + kSurveyOffset;
  const Eigen::Vector3d origin = localOrigin(world);
  const LocalCloud copied = makeLocalCloud(world, origin);
  auto shifted = std::make_shared<Eigen::Matrix3Xd>(world.colwise() - origin);
  const LocalCloud in_place = localCloudOf(shifted, origin);
  ASSERT_TRUE(copied.positions && in_place.positions);
  EXPECT_EQ(in_place.positions.get(), shifted.get());  // the caller's, not a copy
  // Bit for bit (== would take -0 for +0).
  EXPECT_EQ(std::memcmp(in_place.positions->data(), copied.positions->data(),
                        sizeof(double) * world.size()),
            0);
  for (std::size_t i = 0; i < copied.points->size(); ++i)
    ASSERT_EQ(std::memcmp((*in_place.points)[i].data, (*copied.points)[i].data, 12), 0) << i;
  const Eigen::Matrix3Xd back = shifted->colwise() + origin;
  EXPECT_EQ(std::memcmp(back.data(), world.data(), sizeof(double) * world.size()), 0);
}

TEST(LocalCloud, FromFloatRowsItIsMakeLocalCloudsOrNothingWhereTheFloatsWouldRound) {
  // A float file's rows (x, y, z beside other bytes) at survey coordinates: about the local
  // origin the floats hold them exactly, so the cloud made from the rows is makeLocalCloud's of
  // the same coordinates as doubles, bit for bit, organized alike. About an origin that leaves a
  // float's fraction behind it is nothing (points null): the caller makes it from the doubles.
  const Scene scene = makeScene(600);
  struct Row {
    float intensity, x, y, z;
    std::uint32_t tag;
  };
  std::vector<Row> rows(static_cast<std::size_t>(scene.points.cols()));
  Eigen::Matrix3Xd world(3, scene.points.cols());
  for (Eigen::Index i = 0; i < world.cols(); ++i) {
    const Eigen::Vector3f f = ((0.37 * scene.points.col(i)) + kSurveyOffset).cast<float>();
    rows[i] = {1.5f, f.x(), f.y(), f.z(), 7u};
    world.col(i) = f.cast<double>();
  }
  rows[3].y = std::numeric_limits<float>::quiet_NaN();  // kept, NaN, and the cloud not dense
  world(1, 3) = std::numeric_limits<double>::quiet_NaN();
  const std::uint32_t offsets[3] = {4, 8, 12};
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(rows.data());
  const Eigen::Vector3d origin = localOrigin(world);
  const LocalCloud made = makeLocalCloud(world, origin, 20);
  const LocalCloud from_rows =
      localCloudOfFloats(bytes, sizeof(Row), offsets, rows.size(), origin, 20);
  ASSERT_TRUE(from_rows.points);
  EXPECT_FALSE(made.positions);  // the floats hold them: nothing to compare but the points
  EXPECT_FALSE(from_rows.positions);
  EXPECT_EQ(from_rows.origin, origin);
  EXPECT_FALSE(from_rows.points->is_dense);
  EXPECT_EQ(from_rows.points->width, 20u);
  EXPECT_EQ(from_rows.points->height, made.points->height);
  EXPECT_EQ(from_rows.points->sensor_origin_, made.points->sensor_origin_);
  ASSERT_EQ(from_rows.points->size(), made.points->size());
  for (std::size_t i = 0; i < made.points->size(); ++i)
    ASSERT_EQ(std::memcmp((*from_rows.points)[i].data, (*made.points)[i].data, 12), 0) << i;
  // A flat cloud at z = -0: its origin there is -0, and the axis is not moved (-0 stays -0, as
  // the tools' positions keep it).
  std::vector<Row> flat = rows;
  for (Row& row : flat) row.z = -0.0f;
  Eigen::Matrix3Xd flat_world = world;
  flat_world.row(2).setConstant(-0.0);
  const LocalCloud level =
      localCloudOfFloats(reinterpret_cast<const std::uint8_t*>(flat.data()), sizeof(Row), offsets,
                         flat.size(), localOrigin(flat_world));
  ASSERT_TRUE(level.points);
  for (const pcl::PointXYZ& p : *level.points) ASSERT_TRUE(std::signbit(p.z));
  // Half a float's quantum off the power-of-two origin: x - origin needs more bits than a float.
  const Eigen::Vector3d off = origin + Eigen::Vector3d(std::ldexp(1.0, -30), 0.0, 0.0);
  EXPECT_FALSE(localCloudOfFloats(bytes, sizeof(Row), offsets, rows.size(), off).points);
}

// Why the tools never fall back from a float file's rows: about their own local origin, floats
// are always exact. Where the origin o != 0, every coordinate x has |x| >= P (the power of two
// not below the box's side) and |x - o| <= P, o a multiple of P: x and o are multiples of float's
// quantum at P, so x - o is one too and needs at most 24 bits. Clouds of every size and place,
// across 0, on one plane, at -0.
TEST(LocalCloud, FloatRowsAreExactAboutTheirOwnOrigin) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> exponent(-30.0, 30.0), unit(-1.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const double place = (trial % 5 == 0 ? 0.0 : std::exp2(exponent(random))) * unit(random);
    const double side = std::exp2(exponent(random));
    std::vector<float> rows(3 * 64);
    Eigen::Matrix3Xd world(3, 64);
    for (int i = 0; i < 64; ++i)
      for (int d = 0; d < 3; ++d) {
        float value = static_cast<float>(place + side * unit(random));
        if (trial % 7 == 0 && d == 2) value = trial % 2 ? -0.0f : 1.5f;  // one plane
        rows[3 * i + d] = value;
        world(d, i) = value;
      }
    const std::uint32_t offsets[3] = {0, 4, 8};
    const LocalCloud cloud = localCloudOfFloats(reinterpret_cast<const std::uint8_t*>(rows.data()),
                                                12, offsets, 64, localOrigin(world));
    ASSERT_TRUE(cloud.points) << "place " << place << ", side " << side;
    for (int i = 0; i < 64; ++i)
      for (int d = 0; d < 3; ++d) {  // back to the coordinate read, to the bit (-0 too)
        const double back = worldCoordinate((*cloud.points)[i].data[d], cloud.origin[d]);
        ASSERT_EQ(std::memcmp(&back, &world(d, i), sizeof back), 0) << i << ", " << d;
      }
  }
}

// The pixel grid's window sums read the exact coordinates too: an organized height field far
// away, its sensor 30 above its middle, gives the normals it gives at the origin.
TEST(LocalFit, GridNormalsDoNotDependOnWhereTheFrameSits) {
  const Scene scene = makeScene(0);  // 100 x 100, row by row
  LocalFitOptions options = kdTree(LocalFitMethod::PCA, 25);
  options.neighbourhood = NeighbourhoodKind::Grid;
  Eigen::Matrix3Xd a, b;
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d::Zero().eval(), kSurveyOffset}) {
    LocalCloud cloud = makeLocalCloud(scene.points.colwise() + offset, 100);
    const Eigen::Vector3d sensor = offset + Eigen::Vector3d(0.0, 0.0, 30.0);
    std::const_pointer_cast<pcl::PointCloud<pcl::PointXYZ>>(cloud.points)
        ->sensor_origin_.head<3>() = (sensor - cloud.origin).cast<float>();
    options.viewpoint = sensor;
    (offset.isZero() ? a : b) = normalsOf(fitLocalSurfaces(cloud, nullptr, options).normals);
  }
  double worst = 0.0;
  for (Eigen::Index i = 0; i < a.cols(); ++i) worst = std::max(worst, angle(a.col(i), b.col(i)));
  EXPECT_LE(worst, 1e-9);
  EXPECT_LT(angleErrors(b, scene.normals, SignMode::Unsigned).mean, 1.5);  // PCA's own error
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
