// Inner-ball radii: the radius of a sphere, the tube of a torus, half a plate's thickness; nothing
// on an open plane; the same far from the origin, with the faces wound inward, or with a vertex
// doubled.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/surface/inner_ball.h"
#include "pcl_ddg/surface/mesh_smoothing.h"

namespace pcl_ddg {
namespace test {
namespace {

TEST(InnerBall, ASpheresRadiusAndATorusTube) {
  // Only vertices are tested, so a ball can bulge between them by an edge's sagitta (2 % here).
  // A vertex normal tilted by d (radians) from the true one lets the ball out between p and its
  // nearest vertices (at h) unless r <= R / (1 + 2 d R / h): the icospheres' area-weighted
  // normals tilt by up to 2 deg (coarse) and 0.1 deg (fine), which takes up to 20 % off; on the
  // torus, whose normals are exact by symmetry, a few per cent.
  const SurfaceSample sphere = makeIcosphere(2, 2.0);
  const Eigen::VectorXd on_sphere = innerBallRadii(topologyOf(sphere), sphere.points);
  EXPECT_GT(on_sphere.minCoeff(), 2.0 * 0.8);
  EXPECT_LT(on_sphere.maxCoeff(), 2.0 * 1.02);
  const SurfaceSample fine_sphere = makeIcosphere(4, 2.0);
  const Eigen::VectorXd on_fine_sphere =
      innerBallRadii(topologyOf(fine_sphere), fine_sphere.points);
  EXPECT_GT(on_fine_sphere.minCoeff(), 2.0 * 0.8);
  EXPECT_LT(on_fine_sphere.maxCoeff(), 2.0 * 1.02);

  const SurfaceSample torus = makeTorus({96, 0.0, 1}, 1.0, 0.25);
  const Eigen::VectorXd on_torus = innerBallRadii(topologyOf(torus), torus.points);
  EXPECT_GT(on_torus.minCoeff(), 0.25 * 0.97);
  EXPECT_LT(on_torus.maxCoeff(), 0.25 * 1.02);
}

TEST(InnerBall, APlateIsHalfItsThicknessAPlaneUnbounded) {
  // Two parallel sheets 0.2 apart, wound as a slab's faces (outward normals): inside, 0.1.
  const SurfaceSample plane = makePlane({16, 0.0, 1});
  const Eigen::VectorXd open = innerBallRadii(topologyOf(plane), plane.points);
  EXPECT_TRUE(open.array().isInf().all());

  const int n = static_cast<int>(plane.points.cols());
  Eigen::Matrix3Xd x(3, 2 * n);
  x << plane.points.colwise() + Eigen::Vector3d(0, 0, 0.1),
      plane.points.colwise() - Eigen::Vector3d(0, 0, 0.1);
  Eigen::Matrix3Xi triangles(3, 2 * plane.triangles.cols());
  Eigen::Matrix3Xi lower = plane.triangles.array() + n;
  lower.row(1).swap(lower.row(2));  // the lower sheet faces down
  triangles << plane.triangles, lower;
  const Eigen::VectorXd plate = innerBallRadii(MeshTopology(2 * n, triangles), x);
  // Interior vertices only: at the sheets' open edges the ball may leave through the side.
  int interior = 0;
  for (int v = 0; v < 2 * n; ++v) {
    if (x.col(v).head<2>().cwiseAbs().maxCoeff() > 0.8) continue;
    EXPECT_NEAR(plate[v], 0.1, 1e-9) << v;
    ++interior;
  }
  EXPECT_GT(interior, 100);
}

TEST(InnerBall, TheSameFarFromTheOriginWoundInwardOrWithADoubledVertex) {
  const SurfaceSample torus = makeTorus({48, 0.0, 1}, 1.0, 0.3);
  const MeshTopology topology = topologyOf(torus);
  const Eigen::VectorXd radii = innerBallRadii(topology, torus.points);
  ASSERT_TRUE(radii.allFinite());

  SurfaceSample far = torus;
  far.rotateAndShiftFar();
  const Eigen::VectorXd far_radii = innerBallRadii(topology, far.points);
  EXPECT_LT((far_radii - radii).cwiseAbs().maxCoeff(), 1e-6 * radii.maxCoeff());

  Eigen::Matrix3Xi inward = torus.triangles;
  inward.row(1).swap(inward.row(2));
  const Eigen::VectorXd inward_radii =
      innerBallRadii(MeshTopology(static_cast<int>(torus.points.cols()), inward), torus.points);
  EXPECT_EQ(inward_radii, radii);
  // Two far-apart copies, one wound inward: each component finds its own inside.
  const int m = static_cast<int>(torus.points.cols());
  Eigen::Matrix3Xd two(3, 2 * m);
  two << torus.points, torus.points.colwise() + Eigen::Vector3d(10.0, 0.0, 0.0);
  Eigen::Matrix3Xi both(3, 2 * torus.triangles.cols());
  both << torus.triangles, (inward.array() + m).matrix();
  const Eigen::VectorXd two_radii = innerBallRadii(MeshTopology(2 * m, both), two);
  EXPECT_LT((two_radii.head(m) - radii).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((two_radii.tail(m) - radii).cwiseAbs().maxCoeff(), 1e-9);

  // A second copy of vertex 0 (as scans have), in no triangle, and one in a triangle: the ball
  // at vertex 0 is not stopped by its own duplicate.
  const int n = static_cast<int>(torus.points.cols());
  Eigen::Matrix3Xd doubled(3, n + 1);
  doubled << torus.points, torus.points.col(0);
  Eigen::Matrix3Xi with_copy(3, torus.triangles.cols());
  with_copy = torus.triangles;
  for (Eigen::Index t = 0; t < with_copy.cols(); ++t) {
    for (int c = 0; c < 3; ++c) {
      if (with_copy(c, t) == 0 && t % 2 == 0) with_copy(c, t) = n;
    }
  }
  const Eigen::VectorXd isolated_copy =
      innerBallRadii(MeshTopology(n + 1, torus.triangles), doubled);
  EXPECT_TRUE(std::isinf(isolated_copy[n]));
  EXPECT_EQ(isolated_copy.head(n), radii);
  // A near double a millionth inside, sharing vertex 0's triangles, stops vertex 0's ball at
  // half that: a spot kept still.
  Eigen::Matrix3Xd near_double = doubled;
  near_double.col(n) -= 1e-6 * torus.normals.col(0);
  const Eigen::VectorXd near = innerBallRadii(MeshTopology(n + 1, with_copy), near_double);
  EXPECT_LT(near[0], 1e-6);
  EXPECT_GT(near[n], 0.3 * 0.7);
  const Eigen::VectorXd shared_copy = innerBallRadii(MeshTopology(n + 1, with_copy), doubled);
  // Sharing vertex 0's triangles, the copy tilts both normals a little (0.3 * 0.75 on this
  // coarse torus), but neither ball stops at the other (it would be 0).
  EXPECT_GT(shared_copy[0], 0.3 * 0.7);
  EXPECT_GT(shared_copy[n], 0.3 * 0.7);
}

TEST(InnerBall, StartingFromASmallerBallGivesTheSameRadiiBelowIt) {
  // A tangent ball is empty exactly while its radius is at most the vertex's r, and each shrink
  // lands on a radius no smaller: from any start the iteration ends on min(start, r), bit for bit
  // where r is below the start (the same last vertex decides it) by more than the emptiness
  // test's tolerance (1e-9). Starts below, at and above the torus's tube radius.
  const SurfaceSample torus = makeTorus({48, 0.0, 1}, 1.0, 0.3);
  const MeshTopology topology = topologyOf(torus);
  const Eigen::VectorXd radii = innerBallRadii(topology, torus.points);
  for (const double largest : {0.2, 0.3, 0.5, 10.0}) {
    const Eigen::VectorXd capped = innerBallRadii(topology, torus.points, largest);
    int below = 0;
    for (Eigen::Index v = 0; v < radii.size(); ++v) {
      if (radii[v] < largest * (1.0 - 1e-9)) {
        EXPECT_EQ(capped[v], radii[v]) << v << " from " << largest;
        ++below;
      } else if (radii[v] >= largest) {
        EXPECT_EQ(capped[v], largest) << v << " from " << largest;
      } else {  // within the emptiness test's tolerance of the start (the tube's own radius)
        EXPECT_NEAR(capped[v], radii[v], 1e-9 * largest) << v << " from " << largest;
      }
    }
    if (largest >= 0.3) EXPECT_GT(below, radii.size() / 2) << largest;
  }
}

TEST(InnerBall, AnOpenSurfaceKeepsTheSideItsFacesGive) {
  // A cap of a unit sphere (z > 0.3: open, consistently oriented). Wound outward its inner side
  // is the sphere's inside: every ball is the sphere's (radius 1, the 20 % a normal's tilt can
  // take off allowed). Wound inward (normals to the centre) the faces' side is kept as it is on
  // an open surface, although its volume about its vertices' mean is negative: the inner side is
  // outside the sphere, where a ball tangent at p holds no vertex, so every radius is infinite.
  const SurfaceSample sphere = makeIcosphere(3, 1.0);
  std::vector<int> kept;
  for (Eigen::Index t = 0; t < sphere.triangles.cols(); ++t) {
    bool above = true;
    for (int c = 0; c < 3; ++c) above = above && sphere.points(2, sphere.triangles(c, t)) > 0.3;
    if (above) kept.push_back(static_cast<int>(t));
  }
  Eigen::Matrix3Xi outward(3, kept.size());
  for (std::size_t t = 0; t < kept.size(); ++t) outward.col(t) = sphere.triangles.col(kept[t]);
  Eigen::Matrix3Xi inward = outward;
  inward.row(1).swap(inward.row(2));
  const int n = static_cast<int>(sphere.points.cols());
  const MeshTopology out_topology(n, outward), in_topology(n, inward);
  ASSERT_GT(out_topology.counts().boundary_edges, 0);
  ASSERT_TRUE(in_topology.counts().consistently_oriented);
  ASSERT_LT(componentVolumes(in_topology, sphere.points)[0], 0.0);

  const Eigen::VectorXd out_radii = innerBallRadii(out_topology, sphere.points);
  const Eigen::VectorXd in_radii = innerBallRadii(in_topology, sphere.points);
  int on_cap = 0;
  for (int v = 0; v < n; ++v) {
    if (out_topology.isIsolated(v)) continue;
    ++on_cap;
    EXPECT_TRUE(std::isinf(in_radii[v])) << v << ": " << in_radii[v];
    if (out_topology.isBoundary(v)) continue;  // a one-sided normal, tilted: the ball may leave
    EXPECT_GT(out_radii[v], 0.8) << v;
    EXPECT_LT(out_radii[v], 1.02) << v;
  }
  EXPECT_GT(on_cap, 100);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
