// PCL's curvature (surface variation) over mesh 1-rings: zero on planes, PCL's own value on the
// same neighbourhood, and a sphere's known small-ring limit.
#include <gtest/gtest.h>

#include <pcl/features/normal_3d.h>

#include <cmath>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/features/ring_surface_variation.h"
#include "pcl_ddg/io/mesh_io.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

TEST(RingSurfaceVariation, IsZeroOnAJitteredPlaneFarFromTheOrigin) {
  SurfaceSample plane = makePlane({16, 0.2, 3});
  plane.rotateAndShiftFar();
  const Eigen::VectorXd v = ringSurfaceVariation(topologyOf(plane), plane.points);
  EXPECT_LT(v.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(RingSurfaceVariation, EqualsPCLsCurvatureOnTheSameNeighbourhood) {
  const MeshFile bunny = readMeshFile(sharedData("meshes/bunny.off"));
  const MeshTopology topology(bunny.mesh);
  const Eigen::VectorXd ours = ringSurfaceVariation(topology, bunny.positions);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::fromPCLPointCloud2(bunny.mesh.cloud, cloud);
  for (int v = 0; v < topology.numVertices(); ++v) {
    pcl::Indices ring = {v};
    for (const int u : topology.neighbours(v)) ring.push_back(u);
    Eigen::Vector4f plane;
    float pcl_curvature = 0.0f;
    pcl::computePointNormal(cloud, ring, plane, pcl_curvature);
    // PCL forms its covariance in float: agreement to float precision of the ring's spread.
    ASSERT_NEAR(ours[v], pcl_curvature, 1e-4 * (1.0 + ours[v])) << "vertex " << v;
  }
}

TEST(RingSurfaceVariation, ShrinksWithTheSquareOfTheEdgeLengthOnASphere) {
  // A ring of radius h on a unit sphere sags by h^2/2: lambda0 ~ h^4, lambda1 + lambda2 ~ h^2.
  const SurfaceSample coarse = makeIcosphere(3), fine = makeIcosphere(4);
  const double c = ringSurfaceVariation(topologyOf(coarse), coarse.points).mean();
  const double f = ringSurfaceVariation(topologyOf(fine), fine.points).mean();
  EXPECT_GT(f, 0.0);
  EXPECT_NEAR(std::log2(c / f), 2.0, 0.1);
}

TEST(RingSurfaceVariation, IsNaNWithoutAPlane) {
  // A vertex whose ring is one line (a needle triangle's corners all collinear) and an isolated
  // one.
  Eigen::Matrix3Xd p(3, 4);
  p << 0, 1, 2, 5,  //
      0, 0, 0, 5,   //
      0, 0, 0, 5;
  const MeshTopology t(polygonMeshOf({p, (Eigen::Matrix3Xi(3, 1) << 0, 1, 2).finished()}));
  const Eigen::VectorXd v = ringSurfaceVariation(t, p);
  EXPECT_TRUE(std::isnan(v[0]) && std::isnan(v[3]));
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
