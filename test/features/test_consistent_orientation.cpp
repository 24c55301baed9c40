// Orientation by propagation along a minimum spanning tree: randomly flipped normals of closed
// surfaces come back all outward, separate sheets and components are oriented on their own, and
// on the shared scans the result agrees with the orientation of the mesh's faces.
#include <gtest/gtest.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "analytic_surfaces.h"
#include "pcl_ddg/features/consistent_orientation.h"
#include "pcl_ddg/features/local_fit.h"
#include "pcl_ddg/features/normal_orientation.h"
#include "pcl_ddg/features/pca_normal_estimation.h"
#include "pcl_ddg/features/quadric_normal_estimation.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/mesh/vertex_positions.h"
#include "pcl_ddg/search/kd_tree_search.h"
#include "range_images.h"
#include "test_data.h"

namespace pcl_ddg {
namespace {

struct OrientedCloud {
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::PointCloud<pcl::Normal> normals;  ///< the truth
};

void add(OrientedCloud& cloud, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  cloud.points.push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                       static_cast<float>(p.z())));
  const Eigen::Vector3f f = n.normalized().cast<float>();
  cloud.normals.push_back(pcl::Normal(f.x(), f.y(), f.z()));
}

/** Fibonacci points on a sphere, outward normals. */
void addSphere(OrientedCloud& cloud, const Eigen::Vector3d& centre, double radius, int count) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count, r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d n(r * std::cos(golden * i), r * std::sin(golden * i), z);
    add(cloud, centre + radius * n, n);
  }
}

OrientedCloud torus(int around, int tube) {
  OrientedCloud cloud;
  for (int i = 0; i < around; ++i) {
    for (int j = 0; j < tube; ++j) {
      const double u = 2 * M_PI * i / around, v = 2 * M_PI * j / tube;
      const Eigen::Vector3d n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
      add(cloud, Eigen::Vector3d(std::cos(u), std::sin(u), 0.0) + 0.4 * n, n);
    }
  }
  return cloud;
}

/** Flips about half the normals at random; returns how many. */
int scramble(pcl::PointCloud<pcl::Normal>& normals, unsigned seed) {
  std::mt19937 random(seed);
  int flipped = 0;
  for (auto& n : normals) {
    if (random() % 2 == 0) continue;
    n.normal_x = -n.normal_x;
    n.normal_y = -n.normal_y;
    n.normal_z = -n.normal_z;
    ++flipped;
  }
  return flipped;
}

/** Share of normals that agree in sign with the reference, over those whose line is within
 *  min_angle_cosine of the reference's (an orientation means nothing for a wrong line). Exactly
 *  expected_non_finite normals may be NaN (points where the input had none): any other NaN is a
 *  failure, not a point left out. */
double agreement(const pcl::PointCloud<pcl::Normal>& normals,
                 const pcl::PointCloud<pcl::Normal>& reference, float min_angle_cosine = 0.0f,
                 int expected_non_finite = 0) {
  int agree = 0, compared = 0, non_finite = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const float dot = normals[i].getNormalVector3fMap().dot(reference[i].getNormalVector3fMap());
    if (!std::isfinite(dot)) ++non_finite;
    if (!std::isfinite(dot) || std::abs(dot) < min_angle_cosine) continue;
    agree += dot > 0.0f;
    ++compared;
  }
  EXPECT_EQ(non_finite, expected_non_finite) << "non-finite normals among " << normals.size();
  EXPECT_GT(compared, 0);
  return static_cast<double>(agree) / compared;
}

TEST(ConsistentOrientation, SphereAndTorusComeBackAllOutward) {
  OrientedCloud sphere;
  addSphere(sphere, Eigen::Vector3d(0.3, -0.2, 0.1), 1.0, 20000);
  OrientedCloud ring = torus(200, 80);
  for (OrientedCloud* cloud : {&sphere, &ring}) {
    pcl::PointCloud<pcl::Normal> normals = cloud->normals;
    const int scrambled = scramble(normals, 5);
    const ConsistentOrientationReport report = orientNormalsConsistently(cloud->points, normals);
    EXPECT_EQ(agreement(normals, cloud->normals), 1.0);
    EXPECT_EQ(report.components, 1);
    EXPECT_EQ(report.oriented_points, static_cast<std::int64_t>(cloud->points.size()));
    EXPECT_EQ(report.flipped_points, scrambled);
  }
}

TEST(ConsistentOrientation, EstimatedNormalsOfATorusBecomeOutward) {
  // PCA normals (towards the origin, so the outer half points inwards) oriented by the tree.
  OrientedCloud ring = torus(200, 80);
  auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>(ring.points);
  LocalFitResult fit = fitLocalSurfaces(points, nullptr, LocalFitOptions());
  EXPECT_LT(agreement(fit.normals, ring.normals), 0.9);
  orientNormalsConsistently(*points, fit.normals);
  EXPECT_EQ(agreement(fit.normals, ring.normals), 1.0);
}

TEST(ConsistentOrientation, TwoNearbySheetsAreEachConsistent) {
  // Two parallel sheets 3 spacings apart (a thin plate's faces), each oriented on its own:
  // every normal of a sheet points the same way.
  OrientedCloud plate;
  const double h = 0.01;
  for (const double z : {0.0, 3 * h})
    for (int i = 0; i < 100; ++i)
      for (int j = 0; j < 100; ++j) add(plate, {i * h, j * h, z}, {0.0, 0.0, z > 0 ? 1.0 : -1.0});
  pcl::PointCloud<pcl::Normal> normals = plate.normals;
  scramble(normals, 9);
  orientNormalsConsistently(plate.points, normals);
  for (const int sheet : {0, 1}) {
    int up = 0;
    for (int i = sheet * 10000; i < (sheet + 1) * 10000; ++i) up += normals[i].normal_z > 0.0f;
    EXPECT_TRUE(up == 0 || up == 10000) << "sheet " << sheet << ": " << up << " of 10000 up";
  }
}

TEST(ConsistentOrientation, EachComponentOnItsOwn) {
  OrientedCloud spheres;
  for (int s = 0; s < 3; ++s) addSphere(spheres, Eigen::Vector3d(5.0 * s, 0.0, s), 1.0, 4000);
  pcl::PointCloud<pcl::Normal> normals = spheres.normals;
  scramble(normals, 11);
  const ConsistentOrientationReport report = orientNormalsConsistently(spheres.points, normals);
  EXPECT_EQ(report.components, 3);
  EXPECT_EQ(agreement(normals, spheres.normals), 1.0);
  // A viewpoint seeds each component facing it: inside the second sphere, all point inwards.
  ConsistentOrientationOptions inside;
  inside.viewpoint = Eigen::Vector3d(5.0, 0.0, 1.0);
  orientNormalsConsistently(spheres.points, normals, inside);
  int inward = 0;
  for (int i = 4000; i < 8000; ++i)
    inward += normals[i].normal_z * (spheres.points[i].z - 1.0f) < 0;
  EXPECT_GT(inward, 3900);
}

/** A terrain as an aerial survey sees it: ground z = 0.1 sin x on [0, 20]^2 (normals up), and a
 *  thin vertical fin (both faces sampled 0.05 apart, normals +-x) standing on it: the tree steps
 *  across the fin's two faces and, without a reference, flips whole regions. */
OrientedCloud terrainWithFin() {
  OrientedCloud cloud;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      const double x = 0.2 * i, y = 0.2 * j;
      add(cloud, Eigen::Vector3d(x, y, 0.1 * std::sin(x)),
          Eigen::Vector3d(-0.1 * std::cos(x), 0.0, 1.0));
    }
  }
  for (int j = 0; j < 50; ++j) {
    for (int k = 1; k < 20; ++k) {
      for (const double side : {-1.0, 1.0}) {
        add(cloud, Eigen::Vector3d(10.0 + 0.025 * side, 5.0 + 0.2 * j, 0.2 * k),
            Eigen::Vector3d(side, 0.0, 0.0));
      }
    }
  }
  return cloud;
}

TEST(ConsistentOrientation, AReferenceSignsWhatItCanAndTheTreeOnlyTheRest) {
  // With up (or a viewpoint above) as the reference, no point whose normal the reference signs
  // with confidence (|n . d| >= 0.1) is turned against it, whatever the tree says; the fin's
  // faces (|n . up| = 0: ambiguous) are filled in along the tree, each consistent.
  const OrientedCloud terrain = terrainWithFin();
  for (const bool by_viewpoint : {false, true}) {
    SCOPED_TRACE(by_viewpoint ? "viewpoint" : "up");
    pcl::PointCloud<pcl::Normal> normals = terrain.normals;
    scramble(normals, 5);
    ConsistentOrientationOptions options;
    if (by_viewpoint)
      options.viewpoint = Eigen::Vector3d(10.0, 10.0, 2000.0);
    else
      options.up = Eigen::Vector3d::UnitZ();
    const ConsistentOrientationReport report =
        orientNormalsConsistently(terrain.points, normals, options);
    int ground_down = 0;
    for (int i = 0; i < 10000; ++i) ground_down += normals[i].normal_z < 0.0f;
    EXPECT_EQ(ground_down, 0);
    EXPECT_EQ(report.confident_points, 10000);
    EXPECT_GE(report.ambiguous_regions, 1);
    // Each face of the fin is one sign throughout (which sign is the tree's choice).
    for (const double side : {-1.0, 1.0}) {
      int along = 0, faces = 0;
      for (std::size_t i = 10000; i < normals.size(); ++i) {
        if ((terrain.points[i].x - 10.0f) * side < 0.0f) continue;
        ++faces;
        along += normals[i].normal_x * side > 0.0f;
      }
      EXPECT_TRUE(along == 0 || along == faces) << along << " of " << faces;
    }
  }
  // Without a reference the same cloud is one tree seeded at its highest point (the fin's top):
  // the ground is still consistent, but nothing stops a wrong step at the fin from flipping it.
  pcl::PointCloud<pcl::Normal> free = terrain.normals;
  const ConsistentOrientationReport report = orientNormalsConsistently(terrain.points, free);
  EXPECT_EQ(report.confident_points, 0);
  EXPECT_EQ(report.ambiguous_regions, 0);
}

/** A cylinder's side, normals (cos t, sin t, rise) with every other one turned around, under a
 *  cap whose normals lean outwards by lean (inwards when negative), oriented with up = +z. Out:
 *  how many of the side's normals come out as (cos t, sin t, rise). */
int outwardSideUnderACap(double rise, double lean) {
  OrientedCloud cylinder;
  for (int k = 0; k < 40; ++k) {
    for (int a = 0; a < 60; ++a) {
      const double t = 2 * M_PI * a / 60;
      add(cylinder, Eigen::Vector3d(std::cos(t), std::sin(t), 0.1 * k),
          Eigen::Vector3d(std::cos(t), std::sin(t), rise));
    }
  }
  const int side = static_cast<int>(cylinder.points.size());
  for (int r = 1; r < 10; ++r) {
    for (int a = 0; a < 6 * r; ++a) {
      const double t = 2 * M_PI * a / (6 * r), radius = 0.1 * r;
      add(cylinder, Eigen::Vector3d(radius * std::cos(t), radius * std::sin(t), 3.95),
          Eigen::Vector3d(lean * std::cos(t), lean * std::sin(t), 1.0));
    }
  }
  pcl::PointCloud<pcl::Normal> normals = cylinder.normals;
  for (int i = 0; i < side; i += 2) normals[i].getNormalVector3fMap() *= -1.0f;
  ConsistentOrientationOptions options;
  options.up = Eigen::Vector3d::UnitZ();
  const ConsistentOrientationReport report =
      orientNormalsConsistently(cylinder.points, normals, options);
  EXPECT_EQ(report.confident_points, static_cast<std::int64_t>(normals.size()) - side);
  int outward = 0;
  for (int i = 0; i < side; ++i)
    outward +=
        normals[i].getNormalVector3fMap().dot(cylinder.normals[i].getNormalVector3fMap()) > 0.0f;
  return outward;
}

TEST(ConsistentOrientation, AnAmbiguousRegionFacesTheReferenceOnTheWhole) {
  // The side rises 3 degrees (n . up = 0.05 < 0.1: ambiguous) and the cap leans inwards, so its
  // tree edges to the side say "inwards": the side's sum of n . up says outwards, and decides.
  EXPECT_EQ(outwardSideUnderACap(0.05, -0.3), 40 * 60);
  EXPECT_EQ(outwardSideUnderACap(-0.05, -0.3), 0) << "falling 3 degrees: inwards";
}

TEST(ConsistentOrientation, ATieIsBrokenByTheConfidentNeighbours) {
  // Horizontal normals: the side's sum of n . up is 0; the cap's lean decides through the tree.
  EXPECT_EQ(outwardSideUnderACap(0.0, 0.3), 40 * 60);
  EXPECT_EQ(outwardSideUnderACap(0.0, -0.3), 0);
}

TEST(ConsistentOrientation, GridGraphOfARangeImage) {
  // A sphere seen by a camera looking up z: the tree over the pixel grid orients its normals
  // consistently; seeded by the camera, all face it.
  const auto image = test::renderRangeImage(test::RangeScene::Sphere, test::PinholeCamera{});
  pcl::PointCloud<pcl::Normal> normals(image.cloud->width, image.cloud->height);
  pcl::PointCloud<pcl::Normal> truth = normals;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const Eigen::Vector3f n = image.normals[i].cast<float>();
    truth[i] = pcl::Normal(n.x(), n.y(), n.z());
    normals[i] = truth[i];
  }
  scramble(normals, 3);
  OrganizedGridSearch<pcl::PointXYZ> grid;
  grid.setInputCloud(image.cloud);
  ConsistentOrientationOptions options;
  options.viewpoint = Eigen::Vector3d::Zero();
  orientNormalsConsistently(grid, normals, options);
  // The background pixels (no point) have no normal, in the input and out.
  const auto background =
      std::count_if(image.cloud->begin(), image.cloud->end(),
                    [](const pcl::PointXYZ& p) { return !pcl::isXYZFinite(p); });
  EXPECT_GT(background, 0);
  EXPECT_EQ(agreement(normals, truth, 0.0f, static_cast<int>(background)), 1.0);
}

TEST(ConsistentOrientation, AgreesWithTheFacesOfTheSharedScans) {
  // The horse (48k vertices) agrees to 99.9 %, the decimated bunny to 99 %. On the coarse cow
  // (2,762 vertices) and the 1,889- vertex bunny with holes, a thin part (an ear, a leg) is a few
  // points across: its PCA normals and the tree's steps across it are unreliable, and one wrong
  // step turns a whole branch. These shares are floors measured per scan (regression pins), not
  // derived: no bound follows from the method alone, since which branch a wrong step turns depends
  // on the scan. The certain property of the propagation is tested on the analytic shapes above
  // (every normal back, whatever the scrambling).
  const std::pair<const char*, double> scans[] = {{"meshes/bunny.off", 0.985},
                                                  {"meshes/horse.ply", 0.999},
                                                  {"meshes/cow.off", 0.9},
                                                  {"meshes/bun_zipper_res3.ply", 0.95}};
  for (const auto& [name, expected] : scans) {
    const MeshFile file = readMeshFile(test::sharedData(name));
    const MeshTopology topology(file.mesh);
    auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    for (Eigen::Index v = 0; v < file.positions.cols(); ++v) {
      const Eigen::Vector3f p = file.positions.col(v).cast<float>();
      points->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    }
    const Eigen::Matrix3Xd faces = meshOrientationNormals(topology, file.positions);
    pcl::PointCloud<pcl::Normal> reference;
    for (Eigen::Index v = 0; v < faces.cols(); ++v) {
      const Eigen::Vector3f n = faces.col(v).normalized().cast<float>();
      reference.push_back(pcl::Normal(n.x(), n.y(), n.z()));
    }
    LocalFitResult knn = fitLocalSurfaces(points, nullptr, LocalFitOptions());
    pcl::PointCloud<pcl::Normal> on_mesh = knn.normals;
    const ConsistentOrientationReport report = orientNormalsConsistently(*points, knn.normals);
    orientNormalsConsistently(topology, *points, on_mesh);
    // Up to one sign for the whole surface: horse.ply's faces are wound inwards.
    const auto consistency = [&](const pcl::PointCloud<pcl::Normal>& normals) {
      const double share = agreement(normals, reference, 0.5f);
      return std::max(share, 1.0 - share);
    };
    const double by_knn = consistency(knn.normals), by_mesh = consistency(on_mesh);
    std::printf("%s: %.2f%% (k-nearest graph, %.1f%% flipped), %.2f%% (mesh graph)\n", name,
                100 * by_knn, 100 * report.flippedShare(), 100 * by_mesh);
    EXPECT_GT(by_knn, expected) << name;
    EXPECT_GT(by_mesh, expected) << name;
  }
}

TEST(ConsistentOrientation, AnOrientationModeOfTheEstimators) {
  // Viewpoint at the torus's centre: per point, the outer half of the PCA normals points in.
  // As the estimator's orientation mode, over its own kd-tree, they all come out.
  OrientedCloud ring = torus(200, 80);
  auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>(ring.points);
  PCANormalEstimation<pcl::PointXYZ, pcl::Normal> pca;
  pca.setInputCloud(points);
  pca.setSearchMethod(std::make_shared<KdTreeSearch<pcl::PointXYZ>>());
  pca.setKSearch(12);
  pca.setOrientationSpanningTree();
  pcl::PointCloud<pcl::Normal> normals;
  pca.compute(normals);
  EXPECT_EQ(pca.getOrientation(), NormalOrientation::SpanningTree);
  EXPECT_EQ(agreement(normals, ring.normals), 1.0);
  EXPECT_EQ(pca.getOrientationReport().components, 1);
  EXPECT_GT(pca.getOrientationReport().flippedShare(), 0.3);  // the outer half, turned

  // Over a separate search surface the search answers in the surface's indices: refused.
  pca.setSearchSurface(std::make_shared<pcl::PointCloud<pcl::PointXYZ>>(*points));
  pca.compute(normals);
  EXPECT_TRUE(normals.empty());
}

TEST(ConsistentOrientation, EachOrientationOfFitLocalSurfacesOnAMesh) {
  // An icosphere about the origin with outward faces, fitted over its mesh rings: like the faces
  // (out), towards the viewpoint (the origin: in, the faces notwithstanding), along the tree
  // seeded up (out).
  const test::SurfaceSample sphere = test::makeIcosphere(4);
  const auto topology = std::make_shared<const MeshTopology>(static_cast<int>(sphere.points.cols()),
                                                             sphere.triangles);
  auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::PointCloud<pcl::Normal> outward;
  for (Eigen::Index v = 0; v < sphere.points.cols(); ++v) {
    const Eigen::Vector3f p = sphere.points.col(v).cast<float>();
    const Eigen::Vector3f n = sphere.normals.col(v).cast<float>();
    points->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    outward.push_back(pcl::Normal(n.x(), n.y(), n.z()));
  }
  for (const auto& [orientation, expected] :
       {std::pair{NormalOrientation::MeshFaces, 1.0}, std::pair{NormalOrientation::Viewpoint, 0.0},
        std::pair{NormalOrientation::SpanningTree, 1.0}}) {
    LocalFitOptions options;
    options.neighbourhood = NeighbourhoodKind::MeshRings;
    options.orientation = orientation;
    const LocalFitResult fit = fitLocalSurfaces(points, topology, options);
    EXPECT_EQ(agreement(fit.normals, outward), expected) << static_cast<int>(orientation);
  }
}

TEST(ConsistentOrientation, QuadricCurvaturesTurnWithTheirNormals) {
  // Seen from its centre a sphere's normals point in and its curvatures are -1/r; along the tree
  // (seeded up at the top) they point out, and both curvatures become +1/r, with kappa1's
  // direction still a unit tangent.
  constexpr double kRadius = 2.0;
  OrientedCloud sphere;
  addSphere(sphere, Eigen::Vector3d::Zero(), kRadius, 20000);
  auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>(sphere.points);
  QuadricNormalEstimation<pcl::PointXYZ, pcl::Normal> quadric;
  quadric.setInputCloud(points);
  quadric.setSearchMethod(std::make_shared<KdTreeSearch<pcl::PointXYZ>>());
  quadric.setKSearch(20);
  quadric.setViewPoint(0.0f, 0.0f, 0.0f);
  quadric.setOrientationSpanningTree(10, false);
  pcl::PointCloud<pcl::Normal> normals;
  pcl::PointCloud<pcl::PrincipalCurvatures> curvatures;
  quadric.computeWithCurvatures(normals, curvatures);
  EXPECT_EQ(agreement(normals, sphere.normals), 1.0);
  EXPECT_GT(quadric.getOrientationReport().flippedShare(), 0.99);
  for (std::size_t i = 0; i < curvatures.size(); ++i) {
    const pcl::PrincipalCurvatures& c = curvatures[i];
    ASSERT_NEAR(c.pc1, 1.0 / kRadius, 0.01) << i;
    ASSERT_NEAR(c.pc2, 1.0 / kRadius, 0.01) << i;
    ASSERT_GE(c.pc1, c.pc2) << i;
    const Eigen::Vector3f d(c.principal_curvature_x, c.principal_curvature_y,
                            c.principal_curvature_z);
    ASSERT_NEAR(d.norm(), 1.0f, 1e-5f) << i;
    ASSERT_NEAR(d.dot(normals[i].getNormalVector3fMap()), 0.0f, 1e-5f) << i;
  }
}

TEST(ConsistentOrientation, SpanningTreeThroughFitLocalSurfacesOnTheGrid) {
  // A sphere seen by a camera looking along +z. Seeded facing the sensor, the grid's tree keeps
  // the normals facing it; seeded up at the highest (farthest) point, it turns them away:
  // consistent either way, for the pixel-grid fast path and for the quadric's grid search.
  // Compared where the sphere is seen within 70 degrees of head-on: nearer the limb the windows
  // hold a scanline or two, whose planes contain the ray, and no orientation is meaningful.
  const auto image = test::renderRangeImage(test::RangeScene::Sphere, test::PinholeCamera{});
  pcl::PointCloud<pcl::Normal> truth;
  std::vector<std::size_t> seen;
  for (std::size_t i = 0; i < image.normals.size(); ++i) {
    const Eigen::Vector3d ray = -(*image.cloud)[i].getVector3fMap().cast<double>().normalized();
    if (!(image.normals[i].dot(ray) > std::cos(70.0 * M_PI / 180.0))) continue;
    seen.push_back(i);
    const Eigen::Vector3f n = image.normals[i].cast<float>();
    truth.push_back(pcl::Normal(n.x(), n.y(), n.z()));
  }
  ASSERT_GT(seen.size(), 5000u);
  for (const LocalFitMethod method : {LocalFitMethod::PCA, LocalFitMethod::Quadric}) {
    for (const bool facing_sensor : {true, false}) {
      LocalFitOptions options;
      options.method = method;
      options.neighbourhood = NeighbourhoodKind::Grid;
      options.k = 25;
      options.orientation = NormalOrientation::SpanningTree;
      options.seed_facing_viewpoint = facing_sensor;
      const LocalFitResult fit = fitLocalSurfaces(image.cloud, nullptr, options);
      pcl::PointCloud<pcl::Normal> estimated;
      for (const std::size_t i : seen) estimated.push_back(fit.normals[i]);
      EXPECT_EQ(agreement(estimated, truth), facing_sensor ? 1.0 : 0.0);
      EXPECT_GT(fit.orientation.flippedShare(), facing_sensor ? 0.0 : 0.95);
      EXPECT_LT(fit.orientation.flippedShare(), facing_sensor ? 0.05 : 1.0);
    }
  }
}

TEST(ConsistentOrientation, RefusesMismatchedInput) {
  OrientedCloud sphere;
  addSphere(sphere, Eigen::Vector3d::Zero(), 1.0, 100);
  pcl::PointCloud<pcl::Normal> fewer(10, 1);
  EXPECT_THROW(orientNormalsConsistently(sphere.points, fewer), pcl::BadArgumentException);
  ConsistentOrientationOptions options;
  options.k = 0;
  EXPECT_THROW(orientNormalsConsistently(sphere.points, sphere.normals, options),
               pcl::BadArgumentException);
  const std::vector<std::pair<int, int>> leaving = {{0, 1}, {99, 100}};
  EXPECT_THROW(orientNormalsConsistently(sphere.points, sphere.normals, leaving),
               pcl::BadArgumentException);
}

}  // namespace
}  // namespace pcl_ddg
