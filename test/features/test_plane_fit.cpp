// The plane fits against matrices of known eigen-decomposition: fitPlane (Eigen's closed-form
// solver) and fitPlaneNormal (the smallest eigenpair only), across flatness, scale and the
// degenerate cases.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "pcl_ddg/features/plane_fit.h"

namespace pcl_ddg {
namespace test {
namespace {

struct KnownCovariance {
  Eigen::Matrix3d matrix;
  Eigen::Vector3d normal;       ///< eigenvector of the smallest eigenvalue
  Eigen::Vector3d eigenvalues;  ///< ascending
};

KnownCovariance rotated(const Eigen::Vector3d& eigenvalues, std::mt19937& random) {
  std::normal_distribution<double> gaussian;
  const Eigen::Quaterniond rotation =
      Eigen::Quaterniond(gaussian(random), gaussian(random), gaussian(random), gaussian(random))
          .normalized();
  const Eigen::Matrix3d r = rotation.toRotationMatrix();
  return {r * eigenvalues.asDiagonal() * r.transpose(), r.col(0), eigenvalues};
}

double angleBetweenLines(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

TEST(PlaneFit, SmallestEigenpairOfKnownMatricesFromFlatToNearlyIsotropic) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 20000; ++trial) {
    // Flatness l0 / l1 from 1e-9 to 0.9, elongation l1 / l2 from 1e-3 to 1, scale from 1e-12 to
    // 1e12 (squared metres of anything from a micro-scan to a city).
    const double l2 = std::pow(10.0, -12.0 + 24.0 * unit(random));
    const double l1 = l2 * std::pow(10.0, -3.0 * unit(random));
    const double l0 =
        l1 * (trial % 4 == 0 ? 0.9 * unit(random) : std::pow(10.0, -9.0 * unit(random)));
    const KnownCovariance known = rotated({l0, l1, l2}, random);
    const PlaneNormal fast = fitPlaneNormal(known.matrix);
    const PlaneFit full = fitPlane(Eigen::Vector3d::Zero(), known.matrix);
    ASSERT_TRUE(fast.valid) << trial;
    ASSERT_TRUE(full.valid) << trial;
    // A closed form reads the eigenvalues off cos(3 phi) = r, where acos is ill-conditioned near
    // r = 1, the double root that l0 and l1 become next to l2: the smallest eigenvalue is good to
    // rounding * l2 / gap, and its eigenvector, a kernel of A - l0 I, to rounding * (l2 / gap)^2.
    const double gap = (l1 - l0) / l2;
    const double tolerance = 1e-15 / (gap * gap);
    EXPECT_LT(angleBetweenLines(fast.normal, known.normal), tolerance) << trial;
    EXPECT_LT(angleBetweenLines(full.normal, known.normal), tolerance) << trial;
    EXPECT_NEAR(fast.normal.norm(), 1.0, 1e-15);
    const double variation = l0 / (l0 + l1 + l2);
    EXPECT_NEAR(fast.surface_variation, variation, 1e-15 / gap) << trial;
    EXPECT_NEAR(full.surface_variation, variation, 1e-15 / gap) << trial;
  }
}

/** fitPlaneNormals over the given matrices, as PlaneNormals. */
std::vector<PlaneNormal> fitMany(const std::vector<Eigen::Matrix3d>& matrices) {
  const std::size_t n = matrices.size();
  std::vector<double> xx(n), xy(n), xz(n), yy(n), yz(n), zz(n), nx(n), ny(n), nz(n), variation(n);
  std::vector<std::uint8_t> valid(n);
  for (std::size_t i = 0; i < n; ++i) {
    xx[i] = matrices[i](0, 0), xy[i] = matrices[i](0, 1), xz[i] = matrices[i](0, 2);
    yy[i] = matrices[i](1, 1), yz[i] = matrices[i](1, 2), zz[i] = matrices[i](2, 2);
  }
  fitPlaneNormals(static_cast<int>(n),
                  {xx.data(), xy.data(), xz.data(), yy.data(), yz.data(), zz.data()},
                  {nx.data(), ny.data(), nz.data(), variation.data(), valid.data()});
  std::vector<PlaneNormal> planes(n);
  for (std::size_t i = 0; i < n; ++i) {
    planes[i].valid = valid[i] != 0;
    planes[i].normal = Eigen::Vector3d(nx[i], ny[i], nz[i]);
    planes[i].surface_variation = variation[i];
  }
  return planes;
}

TEST(PlaneFit, ManyAtOnceFindTheSmallestEigenpairOfKnownMatrices) {
  // The range above with l0 up to 0.99 l1, where Newton's steps run out and the closed form takes
  // over; in a batch whose length is not a multiple of the vector blocks.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<KnownCovariance> known;
  std::vector<Eigen::Matrix3d> matrices;
  for (int trial = 0; trial < 20011; ++trial) {
    const double l2 = std::pow(10.0, -12.0 + 24.0 * unit(random));
    const double l1 = l2 * std::pow(10.0, -3.0 * unit(random));
    const double l0 =
        l1 * (trial % 4 == 0 ? 0.99 * unit(random) : std::pow(10.0, -9.0 * unit(random)));
    known.push_back(rotated({l0, l1, l2}, random));
    matrices.push_back(known.back().matrix);
  }
  const std::vector<PlaneNormal> planes = fitMany(matrices);
  for (std::size_t i = 0; i < known.size(); ++i) {
    const Eigen::Vector3d& l = known[i].eigenvalues;
    const double gap = (l[1] - l[0]) / l[2];
    ASSERT_TRUE(planes[i].valid) << i;
    EXPECT_LT(angleBetweenLines(planes[i].normal, known[i].normal), 1e-15 / (gap * gap))
        << i << " " << l.transpose() << " closed form "
        << angleBetweenLines(fitPlaneNormal(matrices[i]).normal, known[i].normal);
    EXPECT_NEAR(planes[i].normal.norm(), 1.0, 1e-15);
    EXPECT_NEAR(planes[i].surface_variation, l[0] / l.sum(), 1e-15 / gap) << i;
  }
}

TEST(PlaneFit, ManyAtOnceRejectWhatTheClosedFormRejects) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double infinity = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d line;
  line << 1, 2, 3, 2, 4, 6, 3, 6, 9;  // rank one: all points on a line
  Eigen::Matrix3d poisoned = Eigen::Matrix3d::Identity();
  poisoned(2, 2) = 2.0;
  poisoned(0, 1) = poisoned(1, 0) = nan;
  Eigen::Matrix3d unbounded = poisoned;
  unbounded(0, 1) = unbounded(1, 0) = infinity;
  Eigen::Matrix3d nan_diagonal = Eigen::Matrix3d::Identity();
  nan_diagonal(0, 0) = nan;
  const std::vector<Eigen::Matrix3d> bad = {line,
                                            Eigen::Matrix3d::Zero(),
                                            Eigen::Matrix3d::Identity(),
                                            poisoned,
                                            unbounded,
                                            nan_diagonal,
                                            Eigen::Matrix3d::Constant(infinity)};
  for (const PlaneNormal& plane : fitMany(bad)) EXPECT_FALSE(plane.valid);
  for (const Eigen::Matrix3d& matrix : bad) EXPECT_FALSE(fitPlaneNormal(matrix).valid);
}

TEST(PlaneFit, PointsOnAPlaneHaveItsNormalAndNoVariation) {
  // A tilted square grid of points, far from the origin as scans are, passed relative to a point.
  const Eigen::Vector3d normal = Eigen::Vector3d(1, -2, 3).normalized();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  Eigen::Matrix3Xd points(3, 25);
  for (int i = 0; i < 25; ++i) points.col(i) = 1e-3 * ((i % 5) * u + (i / 5) * v);
  const PlaneNormal fit = fitPlaneNormal(points, 25);
  ASSERT_TRUE(fit.valid);
  EXPECT_LT(angleBetweenLines(fit.normal, normal), 1e-12);
  EXPECT_LT(fit.surface_variation, 1e-15);
}

TEST(PlaneFit, RandomLinesRoundedToDoubleHaveNoPlaneAndThinPlanesDo) {
  // Points on a line in a random direction through a random offset, each coordinate rounded to
  // double: collinear to rounding, so no plane, however the solver's rounding falls at the
  // double zero eigenvalue. A strip a thousandth as wide as it is long is a plane.
  std::mt19937 random(2024);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const auto randomUnit = [&] {
    return Eigen::Vector3d(uniform(random), uniform(random), uniform(random)).normalized();
  };
  int planes_on_lines = 0, normals_on_lines = 0, batched_on_lines = 0, missed_strips = 0;
  constexpr int kTrials = 10000, kPoints = 16;
  std::vector<Eigen::Matrix3d> covariances;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Eigen::Vector3d direction = randomUnit(), offset = 100.0 * uniform(random) * randomUnit();
    const Eigen::Vector3d across = direction.unitOrthogonal();
    Eigen::Matrix3Xd line(3, kPoints), strip(3, kPoints);
    for (int i = 0; i < kPoints; ++i) {
      const double t = uniform(random);
      line.col(i) = offset + t * direction;
      strip.col(i) = offset + t * direction + 1e-3 * uniform(random) * across;
    }
    planes_on_lines += fitPlane(line, kPoints).valid;
    normals_on_lines += fitPlaneNormal(line, kPoints).valid;
    missed_strips += !fitPlane(strip, kPoints).valid + !fitPlaneNormal(strip, kPoints).valid;
    const Eigen::Vector3d centroid = line.rowwise().mean();
    const Eigen::Matrix3Xd centred = line.colwise() - centroid;
    covariances.push_back(centred * centred.transpose() / kPoints);
  }
  std::vector<double> c[6];
  for (const Eigen::Matrix3d& m : covariances) {
    const double entries[6] = {m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)};
    for (int e = 0; e < 6; ++e) c[e].push_back(entries[e]);
  }
  std::vector<double> n[3], variation(kTrials);
  std::vector<std::uint8_t> valid(kTrials);
  for (auto& component : n) component.resize(kTrials);
  fitPlaneNormals(kTrials,
                  {c[0].data(), c[1].data(), c[2].data(), c[3].data(), c[4].data(), c[5].data()},
                  {n[0].data(), n[1].data(), n[2].data(), variation.data(), valid.data()});
  for (const std::uint8_t v : valid) batched_on_lines += v;
  EXPECT_EQ(planes_on_lines, 0);
  EXPECT_EQ(normals_on_lines, 0);
  EXPECT_EQ(batched_on_lines, 0);
  EXPECT_EQ(missed_strips, 0);
}

TEST(PlaneFit, DegenerateNeighbourhoodsHaveNoPlane) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix3Xd line(3, 4);
  line << 0, 1, 2, 3, 0, 2, 4, 6, 0, 3, 6, 9;
  EXPECT_FALSE(fitPlaneNormal(line, 4).valid);
  EXPECT_FALSE(fitPlane(line, 4).valid);
  EXPECT_FALSE(fitPlaneNormal(line, 2).valid);  // fewer than 3 points
  EXPECT_FALSE(fitPlaneNormal(Eigen::Matrix3d::Zero()).valid);
  EXPECT_FALSE(fitPlaneNormal(Eigen::Matrix3d::Identity()).valid);  // isotropic: no direction
  Eigen::Matrix3d poisoned = Eigen::Matrix3d::Identity();
  poisoned(2, 2) = 2.0;
  poisoned(0, 1) = poisoned(1, 0) = nan;
  EXPECT_FALSE(fitPlaneNormal(poisoned).valid);
  poisoned(0, 1) = poisoned(1, 0) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(fitPlaneNormal(poisoned).valid);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
