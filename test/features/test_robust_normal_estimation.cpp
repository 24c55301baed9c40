// Robust normals: exact on planes and on each face of a noise-free cube up to its edges, as good
// as PCA on smooth clean surfaces, invariant under rigid motions, the same for any thread count,
// and NaN (counted) only where no plane exists.
#include <gtest/gtest.h>
#include <pcl/search/kdtree.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/features/plane_fit.h"
#include "pcl_ddg/features/robust_normal_estimation.h"
#include "pcl_ddg/features/robust_plane_fit.h"
#include "pcl_ddg/features/widening_planes.h"
#include "pcl_ddg/large_array.h"

namespace pcl_ddg {
namespace test {
namespace {

using Normals = pcl::PointCloud<pcl::Normal>;
using Robust = RobustNormalEstimation<pcl::PointXYZ, pcl::Normal>;

struct RobustResult {
  Normals normals;
  std::vector<float> scales, confidences;
  std::int64_t failed = 0;
};

/** With a search surface: the same points as a cloud of their own, so every query takes the
 *  path of a point that is not one of the graph's nodes. */
RobustResult robust(const Eigen::Matrix3Xd& points, int k = 0, unsigned int threads = 0,
                    bool separate_surface = false) {
  Robust estimator(threads);
  estimator.setInputCloud(toCloud(points));
  if (separate_surface) estimator.setSearchSurface(toCloud(points));
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  if (k > 0) estimator.setKSearch(k);
  RobustResult r;
  estimator.compute(r.normals);
  r.scales = estimator.getScales();
  r.confidences = estimator.getConfidences();
  r.failed = estimator.getFailedPoints();
  return r;
}

Normals pca(const Eigen::Matrix3Xd& points, int k) {
  PCANormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
  estimator.setInputCloud(toCloud(points));
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  estimator.setKSearch(k);
  Normals normals;
  estimator.compute(normals);
  return normals;
}

/** Unsigned angle, degrees. */
double degreesBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

/** Points uniform on the faces of the cube [-1/2, 1/2]^3 (n per face), with their face's normal
 *  and their distance to the nearest edge. */
struct CubeSample {
  Eigen::Matrix3Xd points, normals;
  Eigen::VectorXd edge_distance;
};

CubeSample sampleCube(int per_face, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  CubeSample c;
  c.points.resize(3, 6 * per_face);
  c.normals.resize(3, 6 * per_face);
  c.edge_distance.resize(6 * per_face);
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const double side = face % 2 ? 0.5 : -0.5;
    for (int i = 0; i < per_face; ++i) {
      const int j = face * per_face + i;
      Eigen::Vector3d p(u(rng), u(rng), u(rng));
      p[axis] = side;
      c.points.col(j) = p;
      c.normals.col(j) = Eigen::Vector3d::Unit(axis) * (side > 0 ? 1.0 : -1.0);
      c.edge_distance[j] =
          std::min(0.5 - std::abs(p[(axis + 1) % 3]), 0.5 - std::abs(p[(axis + 2) % 3]));
    }
  }
  return c;
}

TEST(RobustPlaneFit, NoiseFreePlaneIsExactAndEveryNeighbourCountsFully) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  const Eigen::Vector3d t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
  Eigen::Matrix3Xd points(3, 100);
  for (int i = 0; i < 100; ++i) points.col(i) = u(rng) * t1 + u(rng) * t2;
  points.col(0).setZero();  // the query
  const RobustPlaneFit fit = fitRobustPlane(points, 100);
  ASSERT_TRUE(fit.valid);
  EXPECT_LT(degreesBetween(fit.normal, normal), 1e-9);
  EXPECT_EQ(fit.scale, 100);
  EXPECT_NEAR(fit.confidence, 1.0, 1e-12);
  EXPECT_NEAR(fit.surface_variation, 0.0, 1e-15);
}

TEST(RobustPlaneFit, TooFewOrCollinearPointsHaveNoPlane) {
  Eigen::Matrix3Xd two(3, 2);
  two << 0, 1, 0, 0, 0, 0;
  EXPECT_FALSE(fitRobustPlane(two, 2).valid);
  Eigen::Matrix3Xd line(3, 20);
  for (int i = 0; i < 20; ++i) line.col(i) = Eigen::Vector3d(1.0, 2.0, 3.0) * (i - 10);
  EXPECT_FALSE(fitRobustPlane(line, 20).valid);
  Eigen::Matrix3Xd triangle(3, 3);
  triangle << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  const RobustPlaneFit fit = fitRobustPlane(triangle, 3);
  ASSERT_TRUE(fit.valid);
  EXPECT_LT(degreesBetween(fit.normal, Eigen::Vector3d::UnitZ()), 1e-9);
}

TEST(RobustNormals, OnANoiseFreeCubeEachPointGetsTheNormalOfItsOwnFaceUpToTheEdges) {
  // 3000 points per face: spacing s = 1 / sqrt(3000) = 0.018. A plane fit averages the faces
  // wherever its k neighbours reach across an edge (PCA at k = 18 within about 2.4 s of it);
  // beyond 3 s even the smallest scale the robust fit considers (16) sees one face.
  const CubeSample cube = sampleCube(3000, 11);
  const RobustResult r = robust(cube.points);
  const Eigen::Matrix3Xd normals = normalsOf(r.normals);
  const Normals plane = pca(cube.points, 18);
  const double s = 1.0 / std::sqrt(3000.0);
  int near = 0, near_exact = 0, pca_near_exact = 0, far = 0, far_exact = 0;
  for (Eigen::Index i = 0; i < cube.points.cols(); ++i) {
    const double error = degreesBetween(normals.col(i), cube.normals.col(i));
    const double pca_error =
        degreesBetween(plane[i].getNormalVector3fMap().cast<double>(), cube.normals.col(i));
    if (cube.edge_distance[i] >= 3.0 * s) {
      ++far;
      far_exact += error < 1e-4;
    } else if (cube.edge_distance[i] >= 0.5 * s) {
      ++near;
      near_exact += error < 1e-4;
      pca_near_exact += pca_error < 1e-4;
    }
  }
  EXPECT_EQ(r.failed, 0);
  EXPECT_EQ(far_exact, far);
  // Within three spacings of an edge: the own face for most; PCA for few.
  EXPECT_GE(near_exact, 0.9 * near) << near_exact << " of " << near;
  EXPECT_LT(pca_near_exact, 0.5 * near) << pca_near_exact << " of " << near;
}

TEST(RobustNormals, TheDefaultKIsAppliedNotStoredSoARadiusCanFollow) {
  // PCL refuses a k and a radius together: a default k written into k_ would make a later
  // setRadiusSearch fail ("both radius and K"), every output then missing.
  const CubeSample cube = sampleCube(500, 5);
  Robust estimator;
  estimator.setInputCloud(toCloud(cube.points));
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  Normals by_default, by_radius;
  estimator.compute(by_default);
  EXPECT_EQ(estimator.getKSearch(), 0);
  EXPECT_EQ(by_default.size(), cube.points.cols());
  estimator.setRadiusSearch(0.2);
  estimator.compute(by_radius);
  ASSERT_EQ(by_radius.size(), cube.points.cols());
  EXPECT_EQ(estimator.getFailedPoints(), 0);
  Robust with_k;  // the default is kRobustNormalNeighbours, as if set
  with_k.setInputCloud(toCloud(cube.points));
  with_k.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  with_k.setKSearch(kRobustNormalNeighbours);
  Normals with_k_normals;
  with_k.compute(with_k_normals);
  for (std::size_t i = 0; i < by_default.size(); ++i)
    ASSERT_EQ(by_default[i].getNormalVector3fMap(), with_k_normals[i].getNormalVector3fMap()) << i;
}

TEST(RobustNormals, OnSmoothNoiseFreeSurfacesTheyAreAsAccurateAsPCA) {
  // A sphere of 10242 and a torus of 8192 samples: the robust fit chooses a small scale there
  // (the plane's residual is curvature, not noise), so its error is PCA's at a small k.
  const SurfaceSample sphere = makeIcosphere(5, 1.0, 0.3, 5);
  Sampling sampling;
  sampling.resolution = 128;
  sampling.jitter = 0.3;
  const SurfaceSample torus = makeTorus(sampling);
  for (const SurfaceSample* s : {&sphere, &torus}) {
    const RobustResult r = robust(s->points);
    const AngleErrors ours = angleErrors(normalsOf(r.normals), s->normals, SignMode::Unsigned);
    const AngleErrors plane =
        angleErrors(normalsOf(pca(s->points, 16)), s->normals, SignMode::Unsigned);
    EXPECT_EQ(ours.invalid, 0);
    EXPECT_LE(ours.mean, 1.5 * plane.mean) << ours.mean << " vs PCA " << plane.mean;
    std::printf("robust %.3f deg, PCA k = 16 %.3f deg\n", ours.mean, plane.mean);
  }
}

TEST(RobustNormals, NoisyPlaneUsesTheWholeNeighbourhoodAndBeatsASmallPlaneFit) {
  std::mt19937 rng(8);
  std::normal_distribution<double> noise(0.0, 0.01);
  Sampling sampling;
  sampling.resolution = 100;  // h = 0.02: noise of half the spacing
  SurfaceSample s = makePlane(sampling);
  for (Eigen::Index i = 0; i < s.points.cols(); ++i) s.points(2, i) += noise(rng);
  const RobustResult r = robust(s.points);
  const AngleErrors ours = angleErrors(normalsOf(r.normals), s.normals, SignMode::Unsigned);
  const AngleErrors small =
      angleErrors(normalsOf(pca(s.points, 16)), s.normals, SignMode::Unsigned);
  EXPECT_LT(ours.mean, 0.5 * small.mean) << ours.mean << " vs " << small.mean;
  // The robust fit itself (24 neighbours: below the graph's width, so no plane widens): away from
  // the border every neighbour is within the noise band. With the defaults the planes widen
  // beyond the 96 searched.
  const RobustResult own = robust(s.points, 24);
  const auto innerMean = [&](const std::vector<float>& values) {
    double sum = 0.0;
    int inner = 0;
    for (Eigen::Index i = 0; i < s.points.cols(); ++i) {
      if (s.points.col(i).head<2>().cwiseAbs().maxCoeff() > 0.6) continue;
      sum += values[i];
      ++inner;
    }
    return sum / inner;
  };
  EXPECT_GT(innerMean(own.scales), 0.95 * 24);
  EXPECT_LE(innerMean(own.scales), 24);
  EXPECT_GT(innerMean(own.confidences), 0.8);
  EXPECT_LE(innerMean(own.confidences), 1.0);
  EXPECT_GT(innerMean(r.scales), 2.0 * kRobustNormalNeighbours);
}

TEST(RobustNormals, ARigidMotionFarFromTheOriginMovesTheNormalsWithTheSurface) {
  const CubeSample cube = sampleCube(1500, 4);
  const Eigen::Isometry3d motion =
      Eigen::Translation3d(1000.0, -2000.0, 500.0) *
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized());
  const Eigen::Matrix3Xd moved = motion * cube.points;
  const RobustResult here = robust(cube.points), there = robust(moved);
  const Eigen::Matrix3Xd turned_back = motion.linear().transpose() * normalsOf(there.normals);
  // Float coordinates 2000 from the origin carry rounding noise of 1e-4 (s / 250): the same
  // normals to 0.1 deg but at the 1 % of points next to an edge, where that noise can tip the
  // choice between the faces.
  const Eigen::Matrix3Xd normals = normalsOf(here.normals);
  int differ = 0;
  for (Eigen::Index i = 0; i < cube.points.cols(); ++i)
    differ += degreesBetween(normals.col(i), turned_back.col(i)) > 0.1;
  EXPECT_LE(differ, cube.points.cols() / 100) << differ;
  const AngleErrors a = angleErrors(normals, cube.normals, SignMode::Unsigned);
  const AngleErrors b = angleErrors(turned_back, cube.normals, SignMode::Unsigned);
  EXPECT_NEAR(a.mean, b.mean, 0.1 * a.mean + 0.01);
}

TEST(RobustNormals, OneAndTwoThreadsGiveTheSameBits) {
  const CubeSample cube = sampleCube(800, 9);
  Eigen::Matrix3Xd noisy = cube.points;
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 0.005);
  for (Eigen::Index i = 0; i < noisy.size(); ++i) noisy.data()[i] += noise(rng);
  const RobustResult one = robust(noisy, 0, 1), two = robust(noisy, 0, 2);
  ASSERT_EQ(one.normals.size(), two.normals.size());
  for (std::size_t i = 0; i < one.normals.size(); ++i) {
    EXPECT_EQ(one.normals[i].normal_x, two.normals[i].normal_x);
    EXPECT_EQ(one.normals[i].normal_y, two.normals[i].normal_y);
    EXPECT_EQ(one.normals[i].normal_z, two.normals[i].normal_z);
    EXPECT_EQ(one.normals[i].curvature, two.normals[i].curvature);
  }
  EXPECT_EQ(one.scales, two.scales);
  EXPECT_EQ(one.confidences, two.confidences);
}

TEST(RobustNormals, PointsWithoutAPlaneAreNaNAndCountedTheOthersAreFinite) {
  // A line of 50 points (no plane) far from a 10 x 10 plate: the 40 nearest of a line point are
  // on the line.
  Eigen::Matrix3Xd points(3, 150);
  for (int i = 0; i < 50; ++i) points.col(i) = Eigen::Vector3d(100.0 + i, 0.0, 0.0);
  for (int i = 0; i < 100; ++i) points.col(50 + i) = Eigen::Vector3d(i % 10, i / 10, 0.0);
  const RobustResult r = robust(points, 40);
  EXPECT_EQ(r.failed, 50);
  for (int i = 0; i < 150; ++i) {
    const bool finite = std::isfinite(r.normals[i].normal_x);
    EXPECT_EQ(finite, i >= 50) << i;
    EXPECT_EQ(std::isfinite(r.scales[i]), finite);
    EXPECT_EQ(std::isfinite(r.confidences[i]), finite);
  }
}

TEST(RobustNormals, WithoutKTheNeighbourhoodIsTheDefaultAndARadiusSearchWorksToo) {
  std::mt19937 rng(8);
  std::normal_distribution<double> noise(0.0, 0.01);
  Sampling sampling;
  sampling.resolution = 60;
  SurfaceSample s = makePlane(sampling);
  for (Eigen::Index i = 0; i < s.points.cols(); ++i) s.points(2, i) += noise(rng);
  Robust estimator;
  estimator.setInputCloud(toCloud(s.points));
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  Normals normals;
  estimator.compute(normals);            // no setKSearch: the default
  EXPECT_EQ(estimator.getKSearch(), 0);  // applied, not stored (TheDefaultKIsAppliedNotStored...)
  EXPECT_EQ(estimator.getFailedPoints(), 0);
  const auto largest =
      *std::max_element(estimator.getScales().begin(), estimator.getScales().end());
  EXPECT_GE(largest, kRobustNormalNeighbours);  // a wider plane reports its own, larger scale

  Robust by_radius;
  by_radius.setInputCloud(toCloud(s.points));
  by_radius.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  by_radius.setRadiusSearch(0.15);  // about 60 of the plate's points (h = 1/30)
  by_radius.compute(normals);
  EXPECT_EQ(by_radius.getFailedPoints(), 0);
  const AngleErrors errors = angleErrors(normalsOf(normals), s.normals, SignMode::Unsigned);
  EXPECT_EQ(errors.invalid, 0);
  EXPECT_LT(errors.mean, 2.0);
}

TEST(RobustPlaneFit, SmallAndDegenerateNeighbourhoodsAreFiniteOrInvalidNeverNaN) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int count = 3; count <= 20; ++count) {
    Eigen::Matrix3Xd points(3, count);
    for (int i = 0; i < count; ++i) points.col(i) = Eigen::Vector3d(u(rng), u(rng), 0.01 * u(rng));
    points.col(0).setZero();
    const RobustPlaneFit fit = fitRobustPlane(points, count);
    ASSERT_TRUE(fit.valid) << count;
    EXPECT_TRUE(fit.normal.allFinite() && std::isfinite(fit.surface_variation)) << count;
    EXPECT_GT(std::abs(fit.normal.z()), 0.9) << count;
    EXPECT_GE(fit.scale, 3);
    EXPECT_LE(fit.confidence, 1.0);
  }
  const Eigen::Matrix3Xd same = Eigen::Matrix3Xd::Constant(3, 30, 2.0);  // all coincident
  EXPECT_FALSE(fitRobustPlane(same, 30).valid);
  Eigen::Matrix3Xd doubled(3, 40);  // every point twice
  for (int i = 0; i < 20; ++i)
    doubled.col(2 * i) = doubled.col(2 * i + 1) = Eigen::Vector3d(u(rng), u(rng), 0.0);
  const RobustPlaneFit fit = fitRobustPlane(doubled, 40);
  ASSERT_TRUE(fit.valid);
  EXPECT_LT(degreesBetween(fit.normal, Eigen::Vector3d::UnitZ()), 1e-9);
}

/** Unit sphere of n points uniform by area, Gaussian noise sigma on every coordinate; normals
 *  exact (of the point before the noise). */
SurfaceSample noisySphere(int n, double sigma, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  SurfaceSample s;
  s.points.resize(3, n);
  s.normals.resize(3, n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d u = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    s.normals.col(i) = u;
    s.points.col(i) = u + sigma * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
  }
  return s;
}

TEST(RobustNormals, OnANoisySphereWiderPlanesBeatThePlaneOfTheNeighbourhoodSearched) {
  // 20,000 points (spacing 0.025), noise 0.04 = 1.2 % of the bounding-box diagonal: the
  // PCPNet benchmark's highest level. The residual of a plane of the 96 neighbours searched is all
  // noise, so the planes widen beyond the neighbourhood searched, and average more of it.
  const SurfaceSample s = noisySphere(20000, 0.04, 21);
  const RobustResult r = robust(s.points);
  const AngleErrors ours = angleErrors(normalsOf(r.normals), s.normals, SignMode::Unsigned);
  const AngleErrors searched =
      angleErrors(normalsOf(pca(s.points, kRobustNormalNeighbours)), s.normals, SignMode::Unsigned);
  std::printf("robust %.2f deg, PCA k = %d %.2f\n", ours.mean, kRobustNormalNeighbours,
              searched.mean);
  EXPECT_EQ(ours.invalid, 0);
  EXPECT_LT(ours.mean, 0.8 * searched.mean);
  // Every point took a wider plane: its scale beyond the neighbourhood searched, confidence 1.
  int wide = 0;
  for (std::size_t i = 0; i < r.scales.size(); ++i)
    wide += r.scales[i] > kRobustNormalNeighbours && r.confidences[i] == 1.0f;
  EXPECT_GT(wide, 0.99 * s.points.cols());
}

TEST(WidestPlanes, ANoiseFreeCurvedSurfaceKeepsNoWiderPlaneANoisyPlaneTheWidest) {
  // Bound as the estimator bounds it: the reference level's residual within twice that of a
  // small plane (each node's 16 nearest). On a clean sphere the residual is curvature, growing as
  // r^4: the reference exceeds it and no level is kept. A noisy plane's stays the noise: the
  // widest level is kept, its normal exact to the noise averaged over thousands of points.
  const SurfaceSample clean = noisySphere(5000, 0.0, 3);
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.005);
  Eigen::Matrix3Xd plane(3, 5000);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 5000; ++i) plane.col(i) = Eigen::Vector3d(u(rng), u(rng), noise(rng));
  for (const bool noisy : {false, true}) {
    const Eigen::Matrix3Xd& points = noisy ? plane : clean.points;
    std::vector<Eigen::Vector3d> nodes(points.cols());
    for (Eigen::Index i = 0; i < points.cols(); ++i) nodes[i] = points.col(i);
    pcl::search::KdTree<pcl::PointXYZ> tree;
    tree.setInputCloud(toCloud(points));
    NeighbourGraph graph;
    graph.width = 32;
    pcl::Indices found;
    std::vector<float> distances;
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      tree.nearestKSearch(static_cast<pcl::index_t>(i), 32, found, distances);
      graph.neighbours.insert(graph.neighbours.end(), found.begin(), found.end());
    }
    std::vector<double> bound(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      Eigen::Matrix3Xd nearest(3, 16);
      for (int n = 0; n < 16; ++n) nearest.col(n) = nodes[graph.neighbours[i * 32 + n]];
      bound[i] = 2.0 * fitPlane(nearest, 16).eigenvalues[0] * 16.0 / 14.0;
    }
    std::vector<int> as_nodes(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) as_nodes[i] = static_cast<int>(i);
    const std::vector<WidePlane> planes = widestPlanes(nodes, graph, nodes, as_nodes, {}, bound, 2);
    // The same queries as points of their own, through their rows: the same bits.
    const std::vector<WidePlane> apart =
        widestPlanes(nodes, graph, nodes, std::vector<int>(nodes.size(), -1), graph, bound, 1);
    int kept = 0, widest = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < planes.size(); ++i) {
      ASSERT_EQ(planes[i].level, apart[i].level) << i;
      ASSERT_EQ(planes[i].normal, apart[i].normal) << i;
      kept += planes[i].level >= 0;
      widest += planes[i].level == kWideLevels - 1;
      // Away from the plate's border the widest plane is the plate's.
      if (noisy && planes[i].level >= 0 && nodes[i].head<2>().cwiseAbs().maxCoeff() < 0.5)
        worst = std::max(worst, degreesBetween(planes[i].normal, Eigen::Vector3d::UnitZ()));
    }
    if (noisy) {
      EXPECT_GT(widest, 0.5 * nodes.size()) << widest;
      EXPECT_LT(worst, 0.5) << worst;
    } else {
      EXPECT_EQ(kept, 0) << kept;
    }
  }
}

TEST(RobustNormals, AQueryThatIsNotAPointOfTheSurfaceTakesTheSamePlanes) {
  // setSearchSurface with a copy of the input: every query sums its own row instead of taking
  // its node's moments; the same numbers in the same order give the same bits.
  const SurfaceSample s = noisySphere(4000, 0.02, 6);
  const RobustResult same = robust(s.points), apart = robust(s.points, 0, 0, true);
  for (std::size_t i = 0; i < same.normals.size(); ++i) {
    ASSERT_EQ(same.normals[i].normal_x, apart.normals[i].normal_x) << i;
    ASSERT_EQ(same.normals[i].normal_y, apart.normals[i].normal_y) << i;
    ASSERT_EQ(same.normals[i].normal_z, apart.normals[i].normal_z) << i;
  }
  EXPECT_EQ(same.scales, apart.scales);
}

TEST(RobustNormals, ASubsetOfIndicesGetsTheNormalsOfTheWholeCloud) {
  // The graph is the whole surface's either way; the points not estimated search their own
  // rows (for a k-d tree the first 32 of the 96 are the 32 nearest): the same bits.
  const SurfaceSample s = noisySphere(4000, 0.02, 7);
  const RobustResult all = robust(s.points);
  Robust estimator;
  estimator.setInputCloud(toCloud(s.points));
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  auto some = std::make_shared<pcl::Indices>();
  for (int i = 0; i < 4000; i += 7) some->push_back(i);
  estimator.setIndices(some);
  Normals normals;
  estimator.compute(normals);
  ASSERT_EQ(normals.size(), some->size());
  int wide = 0;
  for (std::size_t n = 0; n < some->size(); ++n) {
    const int i = (*some)[n];
    ASSERT_EQ(normals[n].normal_x, all.normals[i].normal_x) << i;
    ASSERT_EQ(normals[n].normal_y, all.normals[i].normal_y) << i;
    ASSERT_EQ(normals[n].normal_z, all.normals[i].normal_z) << i;
    ASSERT_EQ(estimator.getScales()[n], all.scales[i]) << i;
    wide += all.scales[i] > kRobustNormalNeighbours;
  }
  EXPECT_GT(wide, 0.9 * some->size());  // the comparison covers the wider planes
}

TEST(RobustNormals, PlanesWidenOnlyFromAKNearestSearchOfAtLeastTheGraphsWidth) {
  // The same noisy sphere: with 96 nearest most planes widen; with 24 nearest (fewer than a
  // graph row) or a radius none does, and no scale exceeds the neighbours found.
  const SurfaceSample s = noisySphere(4000, 0.02, 7);
  const RobustResult k96 = robust(s.points), k24 = robust(s.points, 24);
  const auto widest = [](const std::vector<float>& scales) {
    return *std::max_element(scales.begin(), scales.end());
  };
  EXPECT_GT(widest(k96.scales), kRobustNormalNeighbours);
  EXPECT_LE(widest(k24.scales), 24);
  Robust by_radius;
  by_radius.setInputCloud(toCloud(s.points));
  by_radius.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  by_radius.setRadiusSearch(0.2);  // about 40 points (spacing 0.056)
  by_radius.setRadiusSearchMaxNeighbours(200);
  Normals normals;
  by_radius.compute(normals);
  EXPECT_LE(widest(by_radius.getScales()), 200);
  EXPECT_LT(widest(by_radius.getScales()), kWideGraphWidth * (kFirstWideLevel + 1));
}

TEST(RobustPlaneFit, OnAGaussianNoisyPlaneSigmaHatIsTheNoiseAndThreeSigmaKeepNearlyAll) {
  // 200 neighbourhoods of 200 points uniform on a unit disk, Gaussian noise sigma = 0.01 normal to
  // it (a plane at every scale: the whole neighbourhood is used). sigma-hat = 1.4826 x the median
  // absolute residual estimates sigma (|N(0, s)| has median 0.6745 s); the final plane keeps the
  // points within 3 sigma-hat, 2 Phi(3) - 1 = 99.73 % of Gaussian residuals.
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double sigma = 0.01;
  const int count = 200, trials = 200;
  double sigma_hat = 0.0, confidence = 0.0, used = 0.0;
  for (int trial = 0; trial < trials; ++trial) {
    Eigen::Matrix3Xd points(3, count);
    const Eigen::Vector3d query(0.0, 0.0, sigma * gauss(rng));
    points.col(0).setZero();
    for (int i = 1; i < count; ++i) {
      Eigen::Vector2d d;
      do d = Eigen::Vector2d(u(rng), u(rng));
      while (d.squaredNorm() > 1.0);
      points.col(i) = Eigen::Vector3d(d.x(), d.y(), sigma * gauss(rng)) - query;
    }
    const RobustPlaneFit fit = fitRobustPlane(points, count);
    ASSERT_TRUE(fit.valid) << trial;
    sigma_hat += fit.noise / trials;
    confidence += fit.confidence / trials;
    used += static_cast<double>(fit.scale) / trials;
  }
  std::printf("sigma-hat %.4f sigma, confidence %.4f, scale %.1f of %d\n", sigma_hat / sigma,
              confidence, used, count);
  EXPECT_GT(sigma_hat, 0.85 * sigma);
  EXPECT_LT(sigma_hat, 1.15 * sigma);
  EXPECT_GT(confidence, 0.985);
  EXPECT_LE(confidence, 1.0);
  EXPECT_NEAR(used, confidence * count, 1e-9 * count);  // the scale is the points kept
}

TEST(RobustPlaneFit, TheOrderTheNeighboursComeInDoesNotMatter) {
  // The fit takes the neighbours nearest first (nested scales, the nearest few as anchor): a
  // neighbourhood in another order (a mesh ring's, a radius search's) is the same neighbourhood.
  // Noisy points near a ridge, nearest first as a k-d tree gives them, then shuffled: the same
  // fit, bit for bit (distinct distances: no tie to order).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (int trial = 0; trial < 20; ++trial) {
    const int count = 96;
    std::vector<std::pair<double, Eigen::Vector3d>> by_distance;
    for (int i = 0; i < count; ++i) {
      const double x = u(rng), y = u(rng);
      const Eigen::Vector3d p(x, y, 0.6 * std::abs(x - 0.3) - 0.18 + noise(rng));
      by_distance.push_back({p.squaredNorm(), p});
    }
    std::sort(by_distance.begin(), by_distance.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    Eigen::Matrix3Xd nearest_first(3, count);
    for (int i = 0; i < count; ++i) nearest_first.col(i) = by_distance[i].second;
    std::vector<int> order(count);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    Eigen::Matrix3Xd shuffled(3, count);
    for (int i = 0; i < count; ++i) shuffled.col(i) = nearest_first.col(order[i]);
    const RobustPlaneFit a = fitRobustPlane(nearest_first, count);
    const RobustPlaneFit b = fitRobustPlane(shuffled, count);
    ASSERT_TRUE(a.valid) << trial;
    ASSERT_TRUE(b.valid) << trial;
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(a.normal[d], b.normal[d]) << trial;
      EXPECT_EQ(a.centroid[d], b.centroid[d]) << trial;
    }
    EXPECT_EQ(a.scale, b.scale) << trial;
    EXPECT_EQ(a.noise, b.noise) << trial;
    EXPECT_EQ(a.residual, b.residual) << trial;
    EXPECT_EQ(a.surface_variation, b.surface_variation) << trial;
  }
}

TEST(RobustNormals, TheCurvatureIsTheSurfaceVariationOfThePointsOfTheFinalFit) {
  // The noisy plane of NoisyPlaneUsesTheWholeNeighbourhood..., 24 neighbours (no plane widens):
  // where the final fit kept all 24 (scale 24), its curvature is l0 / (l0 + l1 + l2) of their
  // covariance, computed here from the k-d tree's 24 nearest with Eigen's eigensolver.
  std::mt19937 rng(8);
  std::normal_distribution<double> noise(0.0, 0.01);
  Sampling sampling;
  sampling.resolution = 100;
  SurfaceSample s = makePlane(sampling);
  for (Eigen::Index i = 0; i < s.points.cols(); ++i) s.points(2, i) += noise(rng);
  const int k = 24;
  const RobustResult r = robust(s.points, k);
  const auto cloud = toCloud(s.points);
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  pcl::Indices found;
  std::vector<float> distances;
  int compared = 0, differ = 0;
  for (Eigen::Index i = 0; i < s.points.cols(); ++i) {
    if (r.scales[i] != k) continue;
    ASSERT_EQ(tree.nearestKSearch(static_cast<pcl::index_t>(i), k, found, distances), k);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const pcl::index_t j : found) mean += (*cloud)[j].getVector3fMap().cast<double>();
    mean /= k;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const pcl::index_t j : found) {
      const Eigen::Vector3d d = (*cloud)[j].getVector3fMap().cast<double>() - mean;
      covariance += d * d.transpose() / k;
    }
    const Eigen::Vector3d l =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues();
    const double variation = l[0] / l.sum();
    ++compared;
    differ += !(std::abs(r.normals[i].curvature - variation) <= 1e-4 * variation);
  }
  EXPECT_GT(compared, 0.8 * s.points.cols());
  EXPECT_LE(differ, compared / 200) << differ << " of " << compared;
}

TEST(RobustNormals, ConfidenceIsTheScaleOverTheNeighboursFound) {
  // On a clean sphere the fit stays local (scale about 16 of the 96 found) and no plane widens:
  // confidence = scale / 96, not scale over the neighbours of the scale chosen.
  const SurfaceSample s = noisySphere(5000, 0.0, 3);
  const RobustResult r = robust(s.points);
  int local = 0;
  for (std::size_t i = 0; i < r.scales.size(); ++i) {
    ASSERT_LE(r.scales[i], kRobustNormalNeighbours) << i;
    EXPECT_EQ(r.confidences[i],
              static_cast<float>(static_cast<double>(r.scales[i]) / kRobustNormalNeighbours))
        << i;
    local += r.scales[i] <= 32;
  }
  EXPECT_GT(local, 0.9 * r.scales.size());
}

TEST(RobustNormals, PlanesWidenFromExactlyTheGraphsWidth) {
  // k = kWideGraphWidth nearest is enough for the planes to widen (the header: k >= the width).
  const SurfaceSample s = noisySphere(4000, 0.02, 7);
  const RobustResult r = robust(s.points, kWideGraphWidth);
  const float widest = *std::max_element(r.scales.begin(), r.scales.end());
  EXPECT_GT(widest, kWideGraphWidth);
  EXPECT_EQ(r.failed, 0);
}

TEST(RobustNormals, AReachBoundsEveryRowItsWiderPlanesReadAndFollowsItsDefinition) {
  // A noisy plane: the planes widen to the last level. Truth: every node c within twelve steps of
  // q along the rows (their 32 nearest), with its row's radius, lies within the reach:
  // |c - q| + rho_c <= reach (the tiles' certificate rests on it). Definition: the reach is U of
  // the last level tried (widening_planes.h), here the twelfth, formed again from the rows.
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.01);
  Sampling sampling;
  sampling.resolution = 60;  // 3,600 points, h = 0.033
  SurfaceSample s = makePlane(sampling);
  for (Eigen::Index i = 0; i < s.points.cols(); ++i) s.points(2, i) += noise(rng);
  const auto cloud = toCloud(s.points);
  Robust estimator;
  estimator.setInputCloud(cloud);
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  estimator.setReportReaches(true);
  Normals normals;
  estimator.compute(normals);
  const std::vector<double>& reach = estimator.getReaches();
  ASSERT_EQ(reach.size(), cloud->size());

  const int n = static_cast<int>(cloud->size());
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  std::vector<std::vector<int>> rows(n);
  std::vector<double> radius(n, 0.0);
  const auto at = [&](int j) { return (*cloud)[j].getVector3fMap().cast<double>(); };
  for (int j = 0; j < n; ++j) {
    std::vector<float> distances;
    tree.nearestKSearch(*cloud, j, kWideGraphWidth, rows[j], distances);
    for (const int m : rows[j]) radius[j] = std::max(radius[j], (at(m) - at(j)).norm());
  }
  std::vector<double> u(radius), next(n);  // U_0 is the row's radius
  for (int level = 1; level < kWideLevels; ++level) {
    for (int r = 0; r < n; ++r) {
      next[r] = 0.0;
      for (const int m : rows[r]) next[r] = std::max(next[r], (at(m) - at(r)).norm() + u[m]);
    }
    std::swap(u, next);
  }
  const float last = static_cast<float>(kWideGraphWidth * kWideLevels);
  int checked = 0;
  for (int q = 0; q < n; q += 7) {
    if (estimator.getScales()[q] != last) continue;  // kept the last level: tried every level
    ++checked;
    EXPECT_NEAR(reach[q], u[q], 1e-12 * u[q]) << q;
    std::vector<int> hops(n, -1);
    std::vector<int> frontier{q};
    hops[q] = 0;
    double farthest = radius[q];
    for (int h = 1; h < kWideLevels; ++h) {
      std::vector<int> further;
      for (const int r : frontier)
        for (const int m : rows[r])
          if (hops[m] < 0) {
            hops[m] = h;
            further.push_back(m);
            farthest = std::max(farthest, (at(m) - at(q)).norm() + radius[m]);
          }
      frontier = std::move(further);
    }
    EXPECT_GE(reach[q] * (1.0 + 1e-12), farthest) << q;
  }
  EXPECT_GT(checked, n / 7 / 2);  // most points widen to the last level on this noisy plane
}

TEST(WidestPlanes, EqualTheSumsOfWalksOverTheGraphComputedByBruteForce) {
  // widening_planes.h: level l's moments at node j sum the points x_m weighted by the number of
  // (l + 1)-step walks from j to m along the rows, W_l = G^(l + 1) (G_jm = 1 for m in row j).
  // The plane of a level is the PCA of those weighted points; the reference level
  // kFirstWideLevel - 1 must have lambda0 <= largest_reference, and levels from kFirstWideLevel
  // are kept while lambda0 <= kWideGrowth x the reference's. Here: G, the walk counts and the
  // weighted PCA by brute force on 600 nodes of a surface flat for x < 0 and curved beyond (the
  // planes widen far on one side, stop early on the other), with random bounds, some -1.
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  const int n = 600, width = 32;
  std::vector<Eigen::Vector3d> nodes(n);
  for (Eigen::Vector3d& p : nodes) {
    const double x = u(rng), y = u(rng);
    p = Eigen::Vector3d(x, y, 0.5 * std::max(x, 0.0) * std::max(x, 0.0) + noise(rng));
  }
  NeighbourGraph graph;
  graph.width = width;
  for (int j = 0; j < n; ++j) {
    std::vector<std::pair<double, int>> by_distance;
    for (int m = 0; m < n; ++m) by_distance.push_back({(nodes[m] - nodes[j]).squaredNorm(), m});
    std::stable_sort(by_distance.begin(), by_distance.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (int c = 0; c < width; ++c) graph.neighbours.push_back(by_distance[c].second);
  }
  // lambda0 and the normal of every level at every node.
  std::vector<std::vector<double>> lambda0(kWideLevels, std::vector<double>(n));
  std::vector<std::vector<Eigen::Vector3d>> normal(kWideLevels, std::vector<Eigen::Vector3d>(n));
  std::vector<double> walks(static_cast<std::size_t>(n) * n, 0.0), next(walks.size());
  for (int j = 0; j < n; ++j)
    for (int c = 0; c < width; ++c)
      walks[static_cast<std::size_t>(j) * n + graph.neighbours[j * width + c]] += 1.0;
  for (int level = 0; level < kWideLevels; ++level) {
    if (level > 0) {  // W_l(j) = sum over m in row j of W_(l-1)(m)
      std::fill(next.begin(), next.end(), 0.0);
      for (int j = 0; j < n; ++j)
        for (int c = 0; c < width; ++c) {
          const std::size_t row = static_cast<std::size_t>(graph.neighbours[j * width + c]);
          const double* from = &walks[row * n];
          double* to = &next[static_cast<std::size_t>(j) * n];
          for (int m = 0; m < n; ++m) to[m] += from[m];
        }
      std::swap(walks, next);
    }
    for (int j = 0; j < n; ++j) {
      const double* w = &walks[static_cast<std::size_t>(j) * n];
      double total = 0.0;
      Eigen::Vector3d first = Eigen::Vector3d::Zero();
      for (int m = 0; m < n; ++m) {
        total += w[m];
        first += w[m] * (nodes[m] - nodes[j]);
      }
      const Eigen::Vector3d centroid = first / total;
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (int m = 0; m < n; ++m) {
        const Eigen::Vector3d d = nodes[m] - nodes[j] - centroid;
        covariance += (w[m] / total) * d * d.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
      lambda0[level][j] = eigen.eigenvalues()[0];
      normal[level][j] = eigen.eigenvectors().col(0);
    }
  }
  std::vector<double> bound(n);
  std::vector<int> expected(n, -1);
  int borderline = 0;
  const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::abs(b); };
  for (int j = 0; j < n; ++j) {
    const double reference = lambda0[kFirstWideLevel - 1][j];
    bound[j] = j % 10 == 0 ? -1.0 : reference * std::exp(1.5 * u(rng));
    borderline += near(reference, bound[j]);
    if (!(reference <= bound[j])) continue;
    for (int level = kFirstWideLevel; level < kWideLevels; ++level) {
      borderline += near(lambda0[level][j], kWideGrowth * reference);
      if (!(lambda0[level][j] <= kWideGrowth * reference)) break;
      expected[j] = level;
    }
  }
  ASSERT_EQ(borderline, 0);
  std::vector<int> as_nodes(n);
  for (int j = 0; j < n; ++j) as_nodes[j] = j;
  const std::vector<WidePlane> planes = widestPlanes(nodes, graph, nodes, as_nodes, {}, bound, 2);
  const std::vector<WidePlane> apart =
      widestPlanes(nodes, graph, nodes, std::vector<int>(n, -1), graph, bound, 1);
  int none = 0, some = 0, widest = 0;
  for (int j = 0; j < n; ++j) {
    ASSERT_EQ(planes[j].level, expected[j]) << j;
    ASSERT_EQ(apart[j].level, expected[j]) << j;
    none += expected[j] < 0;
    some += expected[j] >= kFirstWideLevel && expected[j] < kWideLevels - 1;
    widest += expected[j] == kWideLevels - 1;
    if (expected[j] < 0) continue;
    EXPECT_LT(degreesBetween(planes[j].normal, normal[expected[j]][j]), 1e-4) << j;
    EXPECT_LT(degreesBetween(apart[j].normal, normal[expected[j]][j]), 1e-4) << j;
  }
  std::printf("no wider plane %d, some levels %d, all levels %d\n", none, some, widest);
  EXPECT_GT(none, n / 10);
  EXPECT_GT(some, n / 20);
  EXPECT_GT(widest, 10);
}

// The graph's rows and the levels' moments live in LargeArray: a block of a huge page or more is
// a mapping of its own (the heap's where huge pages are not allowed: sanitizer builds), a smaller
// one the heap's; growing across the boundary and moving keep
// every value, and a new array is zero-filled either way.
TEST(LargeArray, KeepsItsValuesAcrossTheHugePageBoundary) {
  const std::size_t boundary = detail::kLargeArrayBytes / sizeof(int);
  for (const std::size_t size : {boundary - 1, boundary, 3 * boundary + 5}) {
    detail::LargeArray<int> values(size);
    EXPECT_TRUE(std::all_of(values.begin(), values.end(), [](int v) { return v == 0; }));
    // A mapped block starts on a huge page's boundary: only whole aligned 2 MiB spans get one.
    if (detail::hugePagesAllowed() && size * sizeof(int) >= detail::kLargeArrayBytes)
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(values.data()) % detail::kLargeArrayBytes, 0u);
    for (std::size_t i = 0; i < size; ++i) values[i] = static_cast<int>(i * 7 + 1);
    values.resize(size + boundary);  // across the boundary (from below it) or further above
    detail::LargeArray<int> moved = std::move(values);
    for (std::size_t i = 0; i < size; ++i) ASSERT_EQ(moved[i], static_cast<int>(i * 7 + 1)) << i;
    EXPECT_TRUE(std::all_of(moved.begin() + static_cast<std::ptrdiff_t>(size), moved.end(),
                            [](int v) { return v == 0; }));
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
