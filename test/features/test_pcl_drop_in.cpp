// PCANormalEstimation and QuadricNormalEstimation in place of pcl::NormalEstimation(OMP): the
// same calls give PCL's answers, side by side with PCL on bun0.pcd (the cloud of PCL's own
// tests, whose published values are checked here with PCL's tolerances).
#include <gtest/gtest.h>
#include <pcl/conversions.h>
#include <pcl/features/boundary.h>
#include <pcl/features/fpfh.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/features/shot.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/search/kdtree.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/features/quadric_normal_estimation.h"
#include "pcl_ddg/search/mesh_ring_search.h"
#include "test_data.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pcl_ddg {
namespace test {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Normals = pcl::PointCloud<pcl::Normal>;
using PCA = PCANormalEstimation<pcl::PointXYZ, pcl::Normal>;
using Quadric = QuadricNormalEstimation<pcl::PointXYZ, pcl::Normal>;

Cloud::Ptr bun0() {
  const Cloud::Ptr cloud(new Cloud);
  EXPECT_EQ(pcl::io::loadPCDFile(sharedData("clouds/bun0.pcd"), *cloud), 0);
  EXPECT_EQ(cloud->size(), 397u);
  return cloud;
}

pcl::Indices allIndices(std::size_t n) {
  pcl::Indices indices(n);
  for (std::size_t i = 0; i < n; ++i) indices[i] = static_cast<pcl::index_t>(i);
  return indices;
}

/** Runs any pcl::Feature-shaped normal estimator with PCL's usual calls. */
template <typename Estimator>
Normals estimate(Estimator& estimator, const Cloud::Ptr& cloud,
                 const pcl::search::Search<pcl::PointXYZ>::Ptr& search, int k) {
  estimator.setInputCloud(cloud);
  estimator.setSearchMethod(search);
  estimator.setKSearch(k);
  Normals normals;
  estimator.compute(normals);
  return normals;
}

pcl::search::Search<pcl::PointXYZ>::Ptr kdTree() {
  return std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
}

/** The larger of worst and value, where a NaN value is infinite: std::max(worst, NaN) would
 *  keep worst, and a NaN result would pass every bound. */
template <typename Real>
Real worstOf(Real worst, Real value) {
  return std::isnan(value) ? std::numeric_limits<Real>::infinity() : std::max(worst, value);
}

/** Largest component difference of two normal clouds of the same size; infinite where a normal
 *  or curvature of either is not finite (or the sizes differ). */
float maxComponentDifference(const Normals& a, const Normals& b) {
  EXPECT_EQ(a.size(), b.size());
  if (a.size() != b.size() || a.empty()) return std::numeric_limits<float>::infinity();
  float worst = 0.0f;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!a[i].getNormalVector3fMap().allFinite() || !b[i].getNormalVector3fMap().allFinite() ||
        !std::isfinite(a[i].curvature) || !std::isfinite(b[i].curvature))
      return std::numeric_limits<float>::infinity();
    worst = worstOf(
        worst, (a[i].getNormalVector3fMap() - b[i].getNormalVector3fMap()).cwiseAbs().maxCoeff());
    worst = worstOf(worst, std::abs(a[i].curvature - b[i].curvature));
  }
  return worst;
}

/**
 * A search as PCL's own OpenMP test writes one: it answers the k nearest (by brute force) by
 * writing into the vectors it is given, without resizing them, so it works only if the caller sized
 * them to k first (as pcl::NormalEstimationOMP does). It counts the calls that were not, and the
 * largest OpenMP team it was called from.
 */
class FillOnlySearch : public pcl::search::Search<pcl::PointXYZ> {
 public:
  using Ptr = std::shared_ptr<FillOnlySearch>;
  FillOnlySearch() : pcl::search::Search<pcl::PointXYZ>("FillOnlySearch") {}

  int nearestKSearch(const pcl::PointXYZ& point, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override {
#ifdef _OPENMP
    int team = omp_get_num_threads(), seen = largest_team_.load();
    while (team > seen && !largest_team_.compare_exchange_weak(seen, team)) {
    }
#endif
    if (static_cast<int>(k_indices.size()) < k || static_cast<int>(k_sqr_distances.size()) < k) {
      ++undersized_;
      return 0;
    }
    const Cloud& cloud = *input_;
    std::vector<std::pair<float, pcl::index_t>> order(cloud.size());
    for (std::size_t j = 0; j < cloud.size(); ++j) {
      order[j] = {(cloud[j].getVector3fMap() - point.getVector3fMap()).squaredNorm(),
                  static_cast<pcl::index_t>(j)};
    }
    const int found = std::min<int>(k, static_cast<int>(order.size()));
    std::partial_sort(order.begin(), order.begin() + found, order.end());
    for (int n = 0; n < found; ++n) {
      k_indices[n] = order[n].second;
      k_sqr_distances[n] = order[n].first;
    }
    return found;
  }
  int radiusSearch(const pcl::PointXYZ&, double, pcl::Indices&, std::vector<float>&,
                   unsigned int) const override {
    return 0;
  }

  int undersized() const {
    return undersized_.load();
  }
  int largestTeam() const {
    return largest_team_.load();
  }

 private:
  mutable std::atomic<int> undersized_{0};
  mutable std::atomic<int> largest_team_{0};
};

TEST(PCLDropIn, ComputePointNormalGivesPCLsPlaneOnEveryNeighbourhood) {
  const Cloud::Ptr cloud = bun0();
  // PCL's published values for the plane of the whole of bun0.pcd (test_normal_estimation.cpp),
  // with its tolerance 1e-4; the sign of an unoriented normal is the solver's, PCL's test too
  // compares absolute values.
  const pcl::Indices all = allIndices(cloud->size());
  for (const bool quadric : {false, true}) {
    PCA pca;
    Quadric quadric_estimator;
    const LocalFitEstimation<pcl::PointXYZ, pcl::Normal>& ours =
        quadric
            ? static_cast<const LocalFitEstimation<pcl::PointXYZ, pcl::Normal>&>(quadric_estimator)
            : pca;
    Eigen::Vector4f plane;
    float curvature = 0.0f;
    ASSERT_TRUE(ours.computePointNormal(*cloud, all, plane, curvature));
    EXPECT_NEAR(std::abs(plane[0]), 0.035592, 1e-4);
    EXPECT_NEAR(std::abs(plane[1]), 0.369596, 1e-4);
    EXPECT_NEAR(std::abs(plane[2]), 0.928511, 1e-4);
    EXPECT_NEAR(std::abs(plane[3]), 0.0622552, 1e-4);
    EXPECT_NEAR(curvature, 0.0693136, 1e-4);
    float nx = 0, ny = 0, nz = 0;
    ASSERT_TRUE(ours.computePointNormal(*cloud, all, nx, ny, nz, curvature));
    EXPECT_EQ(Eigen::Vector3f(nx, ny, nz), plane.head<3>());
    EXPECT_NEAR(curvature, 0.0693136, 1e-4);
  }
  // Every point's 15 nearest, side by side with pcl::NormalEstimation::computePointNormal.
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> pcl_estimator;
  PCA ours;
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    pcl::Indices neighbours;
    std::vector<float> distances;
    tree.nearestKSearch(*cloud, static_cast<pcl::index_t>(i), 15, neighbours, distances);
    Eigen::Vector4f by_pcl, by_ours;
    float curvature_pcl = 0, curvature_ours = 0;
    ASSERT_TRUE(pcl_estimator.computePointNormal(*cloud, neighbours, by_pcl, curvature_pcl));
    ASSERT_TRUE(ours.computePointNormal(*cloud, neighbours, by_ours, curvature_ours));
    if (by_ours.head<3>().dot(by_pcl.head<3>()) < 0.0f) by_ours = -by_ours;
    EXPECT_LT((by_ours - by_pcl).cwiseAbs().maxCoeff(), 1e-4) << "point " << i;
    EXPECT_NEAR(curvature_ours, curvature_pcl, 1e-4) << "point " << i;
    EXPECT_NEAR(by_ours.head<3>().norm(), 1.0f, 1e-6);
  }
}

TEST(PCLDropIn, ComputePointNormalNaNRules) {
  // Fewer than 3 indices: false and NaN, for PCL and for ours. A non-finite point (in a cloud that
  // says so, is_dense = false) is skipped by both.
  Cloud cloud;
  cloud.push_back(pcl::PointXYZ(0, 0, 0));
  cloud.push_back(pcl::PointXYZ(1, 0, 0));
  cloud.push_back(pcl::PointXYZ(0, 1, 0));
  cloud.push_back(pcl::PointXYZ(0, 0, std::numeric_limits<float>::quiet_NaN()));
  cloud.push_back(pcl::PointXYZ(1, 1, 0));
  cloud.push_back(pcl::PointXYZ(2, 0, 0));
  cloud.is_dense = false;
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> pcl_estimator;
  PCA ours;
  Eigen::Vector4f plane;
  float curvature = 0.0f;
  for (const pcl::Indices& too_few : {pcl::Indices{}, pcl::Indices{0, 1}}) {
    EXPECT_FALSE(pcl_estimator.computePointNormal(cloud, too_few, plane, curvature));
    EXPECT_FALSE(ours.computePointNormal(cloud, too_few, plane, curvature));
    EXPECT_TRUE(plane.array().isNaN().all());
    EXPECT_TRUE(std::isnan(curvature));
  }
  // The plane z = 0 through the finite points, the NaN one skipped; the normal is +-z, d = 0.
  const pcl::Indices with_nan{0, 1, 3, 2, 4};
  Eigen::Vector4f by_pcl;
  ASSERT_TRUE(pcl_estimator.computePointNormal(cloud, with_nan, by_pcl, curvature));
  ASSERT_TRUE(ours.computePointNormal(cloud, with_nan, plane, curvature));
  EXPECT_NEAR(std::abs(plane.z()), 1.0f, 1e-6);
  EXPECT_NEAR(plane.w(), 0.0f, 1e-6);
  EXPECT_NEAR(std::abs(by_pcl.z()), 1.0f, 1e-6);
  EXPECT_NEAR(curvature, 0.0f, 1e-6);
  // Where ours differs (docs/pcl-drop-in.md): points on one line have no plane. PCL returns true
  // with some normal across the line; ours false and NaN.
  const pcl::Indices on_a_line{0, 1, 5};
  EXPECT_TRUE(pcl_estimator.computePointNormal(cloud, on_a_line, by_pcl, curvature));
  EXPECT_FALSE(ours.computePointNormal(cloud, on_a_line, plane, curvature));
  EXPECT_TRUE(plane.array().isNaN().all());
}

TEST(PCLDropIn, ThreadsAsNormalEstimationOMP) {
  // The constructor's count and setNumberOfThreads are the OpenMP team compute() runs its searches
  // in (0: every core, omp_get_num_procs), and the normals do not depend on it. PCL's published
  // normal of bun0 with k = every point, oriented towards the origin.
  const Cloud::Ptr cloud = bun0();
  const int k = static_cast<int>(cloud->size());
  const auto check = [&](const Normals& normals) {
    ASSERT_EQ(normals.size(), cloud->size());
    for (const pcl::Normal& n : normals) {
      EXPECT_NEAR(n.normal_x, -0.035592, 1e-4);
      EXPECT_NEAR(n.normal_y, -0.369596, 1e-4);
      EXPECT_NEAR(n.normal_z, -0.928511, 1e-4);
      EXPECT_NEAR(n.curvature, 0.0693136, 1e-4);
    }
  };
  Normals single;
  for (const unsigned int threads : {1u, 3u, 0u}) {
    PCA ours(threads);
    EXPECT_EQ(ours.getNumberOfThreads(), threads);
    const auto search = std::make_shared<FillOnlySearch>();
    const Normals normals = estimate(ours, cloud, search, k);
    check(normals);
#ifdef _OPENMP
    EXPECT_EQ(search->largestTeam(),
              threads == 0 ? omp_get_num_procs() : static_cast<int>(threads));
#endif
    if (threads == 1) single = normals;
    EXPECT_EQ(maxComponentDifference(normals, single), 0.0f) << threads << " threads";
  }
  Quadric quadric;
  quadric.setNumberOfThreads(2);
  EXPECT_EQ(quadric.getNumberOfThreads(), 2u);
  quadric.setNumberOfThreads();
  EXPECT_EQ(quadric.getNumberOfThreads(), 0u);
  // PCL's OpenMP estimator, the same calls: the same published normal.
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> pcl_omp(4);
  check(estimate(pcl_omp, cloud, kdTree(), k));
}

TEST(PCLDropIn, NeighbourVectorsAreSizedToKBeforeTheSearch) {
  // A search that only writes into vectors sized for it: every call got k slots, and the normals
  // are those pcl::NormalEstimationOMP computes with the same search.
  const Cloud::Ptr cloud = bun0();
  const auto pcl_search = std::make_shared<FillOnlySearch>();
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> pcl_omp(2);
  const Normals by_pcl = estimate(pcl_omp, cloud, pcl_search, 15);
  EXPECT_EQ(pcl_search->undersized(), 0);
  for (const unsigned int threads : {1u, 2u}) {
    const auto search = std::make_shared<FillOnlySearch>();
    PCA ours(threads);
    const Normals by_ours = estimate(ours, cloud, search, 15);
    EXPECT_EQ(search->undersized(), 0);
    EXPECT_EQ(ours.getFailedPoints(), 0);
    EXPECT_LT(maxComponentDifference(by_ours, by_pcl), 1e-4);
    const auto quadric_search = std::make_shared<FillOnlySearch>();
    Quadric quadric(threads);
    const Normals by_quadric = estimate(quadric, cloud, quadric_search, 15);
    EXPECT_EQ(quadric_search->undersized(), 0);
    EXPECT_EQ(quadric.getFailedPoints(), 0);
  }
}

TEST(PCLDropIn, SensorOriginIsTheViewpointAsInPCL) {
  // The viewpoint as pcl::NormalEstimation keeps it: the origin before a cloud, the cloud's
  // sensor_origin_ once set, setViewPoint's point, and back to the sensor origin; the normals face
  // the same way as PCL's for each.
  const Cloud::Ptr cloud = bun0();
  cloud->sensor_origin_ = Eigen::Vector4f(0.3f, -0.2f, 0.5f, 0.0f);
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> pcl_estimator;
  PCA pca;
  Quadric quadric;
  const auto viewpoint = [](auto& estimator) {
    float x = 0, y = 0, z = 0;
    estimator.getViewPoint(x, y, z);
    return Eigen::Vector3f(x, y, z);
  };
  // PCA: the same sign as PCL's at every point; both: every normal faces the viewpoint.
  const auto check_signs = [&](LocalFitEstimation<pcl::PointXYZ, pcl::Normal>& ours,
                               bool same_as_pcl) {
    const Normals by_pcl = estimate(pcl_estimator, cloud, kdTree(), 15);
    const Normals by_ours = estimate(ours, cloud, kdTree(), 15);
    const Eigen::Vector3f to = viewpoint(ours);
    int agree = 0, facing = 0;
    for (std::size_t i = 0; i < by_pcl.size(); ++i) {
      const Eigen::Vector3f n = by_ours[i].getNormalVector3fMap();
      agree += n.dot(by_pcl[i].getNormalVector3fMap()) > 0.0f;
      facing += n.dot(to - (*cloud)[i].getVector3fMap()) >= 0.0f;
    }
    EXPECT_EQ(facing, static_cast<int>(by_pcl.size()));
    if (same_as_pcl) EXPECT_EQ(agree, static_cast<int>(by_pcl.size()));
  };
  EXPECT_EQ(viewpoint(pca), viewpoint(pcl_estimator));
  EXPECT_EQ(viewpoint(pca), Eigen::Vector3f::Zero());
  for (const bool use_quadric : {false, true}) {
    LocalFitEstimation<pcl::PointXYZ, pcl::Normal>& ours =
        use_quadric ? static_cast<LocalFitEstimation<pcl::PointXYZ, pcl::Normal>&>(quadric) : pca;
    pcl_estimator.useSensorOriginAsViewPoint();
    ours.useSensorOriginAsViewPoint();
    pcl_estimator.setInputCloud(cloud);
    ours.setInputCloud(cloud);
    EXPECT_EQ(viewpoint(ours), Eigen::Vector3f(0.3f, -0.2f, 0.5f));
    EXPECT_EQ(viewpoint(ours), viewpoint(pcl_estimator));
    check_signs(ours, !use_quadric);
    pcl_estimator.setViewPoint(-1.0f, 2.0f, -3.0f);
    ours.setViewPoint(-1.0f, 2.0f, -3.0f);
    EXPECT_EQ(viewpoint(ours), viewpoint(pcl_estimator));
    check_signs(ours, !use_quadric);
    pcl_estimator.useSensorOriginAsViewPoint();
    ours.useSensorOriginAsViewPoint();
    EXPECT_EQ(viewpoint(ours), viewpoint(pcl_estimator));
    check_signs(ours, !use_quadric);
  }
}

// A subclass as one of pcl::NormalEstimation is written: it reads and sets the protected
// viewpoint members directly.
template <typename Base>
class ViewpointSubclass : public Base {
 public:
  Eigen::Vector3f viewpoint() const { return Eigen::Vector3f(this->vpx_, this->vpy_, this->vpz_); }
  void setViewpointMembers(float x, float y, float z) {
    this->vpx_ = x;
    this->vpy_ = y;
    this->vpz_ = z;
  }
};

TEST(PCLDropIn, PtrTypesAndProtectedViewpointMembersAsPCL) {
  static_assert(std::is_same_v<PCA::Ptr, std::shared_ptr<PCA>>);
  static_assert(std::is_same_v<PCA::ConstPtr, std::shared_ptr<const PCA>>);
  static_assert(std::is_same_v<Quadric::Ptr, std::shared_ptr<Quadric>>);
  static_assert(std::is_same_v<Quadric::ConstPtr, std::shared_ptr<const Quadric>>);
  const Cloud::Ptr cloud = bun0();
  cloud->sensor_origin_ = Eigen::Vector4f(0.1f, 0.2f, 0.3f, 0.0f);
  ViewpointSubclass<pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal>> pcl_subclass;
  ViewpointSubclass<PCA> ours;
  pcl_subclass.setInputCloud(cloud);
  ours.setInputCloud(cloud);
  EXPECT_EQ(ours.viewpoint(), pcl_subclass.viewpoint());
  EXPECT_EQ(ours.viewpoint(), Eigen::Vector3f(0.1f, 0.2f, 0.3f));
  // Set from inside (after the cloud, which would copy its sensor origin over them): compute()
  // orients towards them, for both.
  pcl_subclass.setViewpointMembers(0.0f, 0.0f, 10.0f);
  ours.setViewpointMembers(0.0f, 0.0f, 10.0f);
  Normals by_pcl, by_ours;
  for (pcl::Feature<pcl::PointXYZ, pcl::Normal>* estimator :
       std::initializer_list<pcl::Feature<pcl::PointXYZ, pcl::Normal>*>{&pcl_subclass, &ours}) {
    estimator->setSearchMethod(kdTree());
    estimator->setKSearch(15);
  }
  pcl_subclass.compute(by_pcl);
  ours.compute(by_ours);
  for (std::size_t i = 0; i < by_pcl.size(); ++i) {
    const Eigen::Vector3f towards = Eigen::Vector3f(0, 0, 10) - (*cloud)[i].getVector3fMap();
    EXPECT_GE(by_ours[i].getNormalVector3fMap().dot(towards), 0.0f);
    EXPECT_GT(by_ours[i].getNormalVector3fMap().dot(by_pcl[i].getNormalVector3fMap()), 0.0f);
  }
}

/** bun0's coordinates in point type PointT (its other fields left as constructed). */
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr bun0As(const Cloud& xyz) {
  typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  cloud->resize(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    (*cloud)[i].x = xyz[i].x;
    (*cloud)[i].y = xyz[i].y;
    (*cloud)[i].z = xyz[i].z;
  }
  return cloud;
}

/** bun0 as PointT -> NormalT through estimator (k = 15, a kd-tree). */
template <typename PointT, typename NormalT>
pcl::PointCloud<NormalT> normalsOf(pcl::Feature<PointT, NormalT>& estimator, const Cloud& xyz) {
  estimator.setInputCloud(bun0As<PointT>(xyz));
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<PointT>>());
  estimator.setKSearch(15);
  pcl::PointCloud<NormalT> normals;
  estimator.compute(normals);
  EXPECT_EQ(normals.size(), xyz.size());
  return normals;
}

std::vector<Eigen::Vector3d> exactQuadricNormals(const Cloud& cloud, int k);
double unorientedDifference(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/** Our estimators on PointT -> NormalT, linked from the library (no PCL_NO_PRECOMPILE): the PCA
 *  normals against pcl::NormalEstimation's on the same pair (largest component difference,
 *  infinite if a normal of either is not finite), the quadric's unit and within 1e-5 per
 *  component of the long-double oracle's (exact: exactQuadricNormals of xyz, k = 15). */
template <typename PointT, typename NormalT>
float pairAgainstPCL(const Cloud& xyz, const std::vector<Eigen::Vector3d>& exact) {
  PCANormalEstimation<PointT, NormalT> ours;
  QuadricNormalEstimation<PointT, NormalT> quadric;
  pcl::NormalEstimation<PointT, NormalT> reference;
  const pcl::PointCloud<NormalT> by_ours = normalsOf(ours, xyz);
  const pcl::PointCloud<NormalT> by_quadric = normalsOf(quadric, xyz);
  const pcl::PointCloud<NormalT> by_pcl = normalsOf(reference, xyz);
  if (by_ours.size() != xyz.size() || by_pcl.size() != xyz.size() ||
      by_quadric.size() != xyz.size())
    return std::numeric_limits<float>::infinity();
  float worst = 0.0f;
  double quadric_from_exact = 0.0;
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    worst = worstOf(worst, (by_ours[i].getNormalVector3fMap() - by_pcl[i].getNormalVector3fMap())
                               .cwiseAbs()
                               .maxCoeff());
    EXPECT_NEAR(by_quadric[i].getNormalVector3fMap().norm(), 1.0f, 1e-6) << "point " << i;
    quadric_from_exact =
        worstOf(quadric_from_exact,
                unorientedDifference(by_quadric[i].getNormalVector3fMap().template cast<double>(),
                                     exact[i]));
  }
  EXPECT_LT(quadric_from_exact, 1e-5);
  return worst;
}

TEST(PCLDropIn, PCLsPointTypePairsLinkFromTheLibrary) {
  // Pairs outside the library's former list (PointXYZ, I, RGB, RGBA and the normal types x
  // Normal, PointNormal, XYZI-, XYZRGBNormal): linked from the precompiled library, and the PCA
  // normals are PCL's (k = 15, within PCL's 1e-4).
  const Cloud::Ptr xyz = bun0();
  const std::vector<Eigen::Vector3d> exact = exactQuadricNormals(*xyz, 15);
  EXPECT_LT((pairAgainstPCL<pcl::PointXYZL, pcl::Normal>(*xyz, exact)), 1e-4);
  EXPECT_LT((pairAgainstPCL<pcl::PointSurfel, pcl::PointSurfel>(*xyz, exact)), 1e-4);
  EXPECT_LT((pairAgainstPCL<pcl::PointXYZRGBL, pcl::PointXYZLNormal>(*xyz, exact)), 1e-4);
  EXPECT_LT((pairAgainstPCL<pcl::PointWithViewpoint, pcl::PointNormal>(*xyz, exact)), 1e-4);
  EXPECT_LT((pairAgainstPCL<pcl::PointDEM, pcl::PointXYZINormal>(*xyz, exact)), 1e-4);
  EXPECT_LT((pairAgainstPCL<pcl::InterestPoint, pcl::PointXYZRGBNormal>(*xyz, exact)), 1e-4);
}

/**
 * The quadric normal of quadric_fit.h computed independently in long double: the k nearest by
 * brute force, the plane from Eigen's long-double eigensolver, the six coefficients by a
 * column-pivoting QR. What an exact fit makes of the cloud as given, whatever its rounding.
 */
std::vector<Eigen::Vector3d> exactQuadricNormals(const Cloud& cloud, int k) {
  using Real = long double;
  using Vector3r = Eigen::Matrix<Real, 3, 1>;
  std::vector<Eigen::Vector3d> normals(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::vector<std::pair<Real, std::size_t>> order(cloud.size());
    for (std::size_t j = 0; j < cloud.size(); ++j)
      order[j] = {(cloud[j].getVector3fMap() - cloud[i].getVector3fMap()).squaredNorm(), j};
    std::partial_sort(order.begin(), order.begin() + k, order.end());
    Eigen::Matrix<Real, 3, Eigen::Dynamic> points(3, k);
    for (int n = 0; n < k; ++n)
      points.col(n) = cloud[order[n].second].getVector3fMap().cast<double>().cast<Real>();
    const Vector3r centroid = points.rowwise().mean();
    const Eigen::Matrix<Real, 3, Eigen::Dynamic> centred = points.colwise() - centroid;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, 3, 3>> eigen(centred *
                                                                         centred.transpose());
    const Vector3r t1 = eigen.eigenvectors().col(2), t2 = eigen.eigenvectors().col(1),
                   n = eigen.eigenvectors().col(0);
    Eigen::Matrix<Real, Eigen::Dynamic, 6> design(k, 6);
    Eigen::Matrix<Real, Eigen::Dynamic, 1> height(k);
    for (int m = 0; m < k; ++m) {
      const Real u = centred.col(m).dot(t1), v = centred.col(m).dot(t2);
      design.row(m) << u * u, u * v, v * v, u, v, 1;
      height(m) = centred.col(m).dot(n);
    }
    const Eigen::Matrix<Real, 6, 1> c = design.colPivHouseholderQr().solve(height);
    const Vector3r at = cloud[i].getVector3fMap().cast<double>().cast<Real>() - centroid;
    const Real u = at.dot(t1), v = at.dot(t2);
    const Real fu = 2 * c(0) * u + c(1) * v + c(3), fv = c(1) * u + 2 * c(2) * v + c(4);
    normals[i] = (n - fu * t1 - fv * t2).normalized().cast<double>();
  }
  return normals;
}

/** Largest component difference of two normals up to their sign. */
double unorientedDifference(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::min((a - b).cwiseAbs().maxCoeff(), (a + b).cwiseAbs().maxCoeff());
}

TEST(PCLDropIn, FarFromOriginAsPCLsTestAndTheQuadricLosesNothingToTheOffset) {
  // PCL's FarFromOrigin case: bun0 moved by (123, -45, 98), k = 15, the viewpoint moved with it.
  // Moving a float cloud rounds every coordinate (to 3.8e-6 near 100), a change of the input; PCL
  // allows 5e-4 per normal component for it, and the PCA estimator meets that.
  const Cloud::Ptr cloud = bun0();
  const Cloud::Ptr far(new Cloud(*cloud));
  const Cloud::Ptr rounded_near(new Cloud(*cloud));
  const Eigen::Vector3d offset(123.0, -45.0, 98.0);
  for (std::size_t i = 0; i < far->size(); ++i) {
    (*far)[i].x += 123.0f;
    (*far)[i].y += -45.0f;
    (*far)[i].z += 98.0f;
    // The rounded points moved back: exact, a multiple of 2^-17 below 0.2 fits a float.
    (*rounded_near)[i].getVector3fMap() =
        ((*far)[i].getVector3fMap().cast<double>() - offset).cast<float>();
  }
  const auto run = [](auto tag, const Cloud::Ptr& input, const Eigen::Vector3d& viewpoint) {
    typename decltype(tag)::type estimator;
    estimator.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
    return estimate(estimator, input, kdTree(), 15);
  };
  const std::common_type<PCA> pca;
  const std::common_type<Quadric> quadric;
  const Normals pca_near = run(pca, cloud, Eigen::Vector3d::Zero());
  const Normals pca_far = run(pca, far, offset);
  for (std::size_t i = 0; i < pca_near.size(); ++i) {
    EXPECT_NEAR(std::abs(pca_near[i].getNormalVector3fMap().dot(pca_far[i].getNormalVector3fMap())),
                1.0, 1e-6);
    EXPECT_LT((pca_near[i].getNormalVector3fMap() - pca_far[i].getNormalVector3fMap())
                  .cwiseAbs()
                  .maxCoeff(),
              5e-4)
        << "point " << i;
  }
  // The quadric far from the origin gives, bit for bit, what it gives on the same rounded points
  // near it: its arithmetic is centred in double and loses nothing to the offset; the rest is the
  // rounding of the input, which its second-order fit amplifies more than the plane (docs).
  const Normals quadric_far = run(quadric, far, offset);
  const Normals quadric_rounded_near = run(quadric, rounded_near, Eigen::Vector3d::Zero());
  EXPECT_EQ(maxComponentDifference(quadric_far, quadric_rounded_near), 0.0f);
  const Normals pca_rounded_near = run(pca, rounded_near, Eigen::Vector3d::Zero());
  EXPECT_EQ(maxComponentDifference(pca_far, pca_rounded_near), 0.0f);
  // PCL's 5e-4 is out of reach of any exact quadric fit: the long-double oracle on the rounded
  // points moves that far from itself on the original ones, and ours follows the oracle.
  const std::vector<Eigen::Vector3d> exact_near = exactQuadricNormals(*cloud, 15);
  const std::vector<Eigen::Vector3d> exact_rounded = exactQuadricNormals(*rounded_near, 15);
  double rounding_moves = 0.0, ours_from_exact = 0.0;
  ASSERT_EQ(quadric_far.size(), cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    rounding_moves = worstOf(rounding_moves, unorientedDifference(exact_near[i], exact_rounded[i]));
    ours_from_exact = worstOf(
        ours_from_exact, unorientedDifference(quadric_far[i].getNormalVector3fMap().cast<double>(),
                                              exact_rounded[i]));
  }
  ASSERT_TRUE(std::isfinite(rounding_moves)) << "the oracle gave a NaN normal";
  EXPECT_GT(rounding_moves, 5e-4);
  EXPECT_LT(ours_from_exact, 1e-6);
}

/** FPFH, SHOT and boundary flags of cloud with normals, each with a fresh search from make. */
struct PCLFeatures {
  pcl::PointCloud<pcl::FPFHSignature33> fpfh;
  pcl::PointCloud<pcl::SHOT352> shot;
  pcl::PointCloud<pcl::Boundary> boundary;
};

template <typename MakeSearch>
PCLFeatures pclFeatures(const Cloud::Ptr& cloud, const Normals::Ptr& normals, int k, double radius,
                        MakeSearch make_search) {
  PCLFeatures out;
  pcl::FPFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> fpfh;
  fpfh.setInputCloud(cloud);
  fpfh.setInputNormals(normals);
  fpfh.setSearchMethod(make_search());
  fpfh.setKSearch(k);
  fpfh.compute(out.fpfh);
  pcl::SHOTEstimation<pcl::PointXYZ, pcl::Normal, pcl::SHOT352> shot;
  shot.setInputCloud(cloud);
  shot.setInputNormals(normals);
  shot.setSearchMethod(make_search());
  shot.setRadiusSearch(radius);
  shot.compute(out.shot);
  pcl::BoundaryEstimation<pcl::PointXYZ, pcl::Normal, pcl::Boundary> boundary;
  boundary.setInputCloud(cloud);
  boundary.setInputNormals(normals);
  boundary.setSearchMethod(make_search());
  boundary.setKSearch(k);
  boundary.compute(out.boundary);
  return out;
}

/** How many descriptors have a non-finite entry. */
int nonFinite(const PCLFeatures& f) {
  int count = 0;
  for (const auto& d : f.fpfh)
    count += !std::all_of(d.histogram, d.histogram + 33, [](float v) { return std::isfinite(v); });
  for (const auto& d : f.shot) {
    count +=
        !std::all_of(d.descriptor, d.descriptor + 352, [](float v) { return std::isfinite(v); });
  }
  return count;
}

TEST(PCLDropIn, PCLsFeaturesRunOnOurNormals) {
  // FPFH, SHOT and boundary estimation take our normals as they take PCL's. With a kd-tree, the
  // results equal those from pcl::NormalEstimation's normals within PCL's tolerances for them
  // (test_shot_estimation: 1e-4; boundary flags exact; FPFH below).
  const Cloud::Ptr cloud = bun0();
  const int k = 15;
  const double radius = 0.02;
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> pcl_estimator;
  const Normals::Ptr pcl_normals(new Normals(estimate(pcl_estimator, cloud, kdTree(), k)));
  const auto make_tree = [] { return kdTree(); };
  const PCLFeatures reference = pclFeatures(cloud, pcl_normals, k, radius, make_tree);
  ASSERT_EQ(nonFinite(reference), 0);
  for (const bool quadric : {false, true}) {
    PCA pca;
    Quadric quadric_estimator;
    const Normals::Ptr normals(new Normals(quadric ? estimate(quadric_estimator, cloud, kdTree(), k)
                                                   : estimate(pca, cloud, kdTree(), k)));
    const PCLFeatures ours = pclFeatures(cloud, normals, k, radius, make_tree);
    EXPECT_EQ(nonFinite(ours), 0);
    ASSERT_EQ(ours.fpfh.size(), cloud->size());
    ASSERT_EQ(ours.shot.size(), cloud->size());
    ASSERT_EQ(ours.boundary.size(), cloud->size());
    if (quadric) continue;  // its normals are not PCL's: finite is what is asked of them
    // FPFH bins are steps: moving PCL's own normals by one float ulp (1.2e-7) changes up to 4
    // units in a bin of PCL's FPFH on bun0 (measured), and ours differ from PCL's by 8e-7; what
    // stays is what FPFH is for: each point's descriptor is nearest to its own.
    float shot = 0.0f;
    int boundary_differs = 0, fpfh_mismatched = 0;
    for (std::size_t i = 0; i < cloud->size(); ++i) {
      const Eigen::Map<const Eigen::Matrix<float, 33, 1>> mine(ours.fpfh[i].histogram);
      std::size_t nearest = 0;
      float best = std::numeric_limits<float>::infinity();
      for (std::size_t j = 0; j < cloud->size(); ++j) {
        const float d =
            (mine - Eigen::Map<const Eigen::Matrix<float, 33, 1>>(reference.fpfh[j].histogram))
                .squaredNorm();
        if (d < best) best = d, nearest = j;
      }
      fpfh_mismatched += nearest != i;
      for (int b = 0; b < 352; ++b)
        shot =
            std::max(shot, std::abs(ours.shot[i].descriptor[b] - reference.shot[i].descriptor[b]));
      boundary_differs += ours.boundary[i].boundary_point != reference.boundary[i].boundary_point;
    }
    EXPECT_EQ(fpfh_mismatched, 0);
    EXPECT_LT(shot, 1e-4);
    EXPECT_EQ(boundary_differs, 0);
  }

  // On a mesh, normals and features all from MeshRingSearch: every descriptor finite.
  pcl::PolygonMesh mesh;
  ASSERT_EQ(pcl::io::loadPLYFile(sharedData("meshes/bun_zipper_res4.ply"), mesh), 0);
  const Cloud::Ptr vertices(new Cloud);
  pcl::fromPCLPointCloud2(mesh.cloud, *vertices);
  const auto rings = std::make_shared<MeshRingSearch<pcl::PointXYZ>>(mesh);
  const auto make_rings = [&] { return std::make_shared<MeshRingSearch<pcl::PointXYZ>>(mesh); };
  for (const bool quadric : {false, true}) {
    PCA pca;
    Quadric quadric_estimator;
    const Normals::Ptr normals(new Normals(quadric ? estimate(quadric_estimator, vertices, rings, k)
                                                   : estimate(pca, vertices, rings, k)));
    EXPECT_EQ(quadric ? quadric_estimator.getFailedPoints() : pca.getFailedPoints(), 0);
    const PCLFeatures ours = pclFeatures(vertices, normals, k, 0.03, make_rings);
    ASSERT_EQ(ours.fpfh.size(), vertices->size());
    EXPECT_EQ(nonFinite(ours), 0);
  }
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
