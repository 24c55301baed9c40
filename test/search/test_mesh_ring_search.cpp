// MeshRingSearch against an independent breadth-first search, PCL's own estimators running on it
// unchanged, topological versus Euclidean balls, and bad queries.
#include <gtest/gtest.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <limits>
#include <queue>
#include <set>

#include "analytic_surfaces.h"
#include "estimator_support.h"
#include "pcl_ddg/search/mesh_ring_search.h"

namespace pcl_ddg {
namespace test {
namespace {

using Search = MeshRingSearch<pcl::PointXYZ>;

// Hop distance from source to every vertex, by a plain BFS over the triangles' edges.
std::vector<int> hopDistances(const Eigen::Matrix3Xi& triangles, int num_vertices, int source) {
  std::vector<std::set<int>> adjacent(num_vertices);
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    for (int k = 0; k < 3; ++k) {
      adjacent[triangles(k, t)].insert(triangles((k + 1) % 3, t));
      adjacent[triangles((k + 1) % 3, t)].insert(triangles(k, t));
    }
  }
  std::vector<int> hops(num_vertices, std::numeric_limits<int>::max());
  std::queue<int> queue;
  hops[source] = 0;
  queue.push(source);
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop();
    for (const int w : adjacent[v]) {
      if (hops[w] > hops[v] + 1) {
        hops[w] = hops[v] + 1;
        queue.push(w);
      }
    }
  }
  return hops;
}

TEST(MeshRingSearch, NearestKIsWholeRingsThenTheNearestOfTheLastRing) {
  const SurfaceSample s = makeTorus({24, 0.2, 3});
  const auto cloud = toCloud(s.points);
  Search search(topologyPtrOf(s));
  search.setInputCloud(cloud);
  const int n = static_cast<int>(s.points.cols());
  pcl::Indices found;
  std::vector<float> distances;
  for (const int query : {0, 17, n / 2, n - 1}) {
    const std::vector<int> hops = hopDistances(s.triangles, n, query);
    for (const int k : {1, 5, 7, 12, 19, 40}) {
      ASSERT_EQ(search.nearestKSearch(query, k, found, distances), k);
      EXPECT_EQ(found[0], query);
      const int last_ring = hops[found.back()];
      std::set<int> chosen(found.begin(), found.end());
      EXPECT_EQ(chosen.size(), found.size()) << "no vertex twice";
      float farthest_chosen_in_last_ring = 0.0f;
      for (std::size_t i = 0; i < found.size(); ++i) {
        EXPECT_LE(hops[found[i]], last_ring);
        if (i > 0) EXPECT_GE(hops[found[i]], hops[found[i - 1]]) << "ring order";
        EXPECT_NEAR(distances[i], (s.points.col(found[i]) - s.points.col(query)).squaredNorm(),
                    1e-5);
        if (hops[found[i]] == last_ring)
          farthest_chosen_in_last_ring = std::max(farthest_chosen_in_last_ring, distances[i]);
      }
      for (int v = 0; v < n; ++v) {
        if (hops[v] < last_ring) EXPECT_TRUE(chosen.count(v)) << "inner rings are complete";
        if (hops[v] == last_ring && !chosen.count(v)) {
          EXPECT_GE((s.points.col(v) - s.points.col(query)).squaredNorm(),
                    farthest_chosen_in_last_ring - 1e-6);
        }
      }
    }
  }
}

TEST(MeshRingSearch, ReturnsFewerThanKOnASmallComponent) {
  Eigen::Matrix3Xd p(3, 6);
  p << 0, 1, 0, 5, 6, 5,  //
      0, 0, 1, 0, 0, 1,   //
      0, 0, 0, 0, 0, 0;
  Eigen::Matrix3Xi tris(3, 2);
  tris << 0, 3, 1, 4, 2, 5;
  Search search(std::make_shared<const MeshTopology>(6, tris));
  search.setInputCloud(toCloud(p));
  pcl::Indices found;
  std::vector<float> distances;
  EXPECT_EQ(search.nearestKSearch(0, 10, found, distances), 3);
  EXPECT_EQ(std::set<int>(found.begin(), found.end()), (std::set<int>{0, 1, 2}));
}

TEST(MeshRingSearch, RadiusSearchIsATopologicalBall) {
  // Two parallel plates 0.05 apart: the Euclidean ball reaches the other plate, the topological
  // one never does.
  SurfaceSample lower = makePlane({16, 0.0, 1});
  const int n = static_cast<int>(lower.points.cols());
  Eigen::Matrix3Xd points(3, 2 * n);
  points << lower.points, lower.points.colwise() + Eigen::Vector3d(0, 0, 0.05);
  Eigen::Matrix3Xi tris(3, 2 * lower.triangles.cols());
  tris << lower.triangles, lower.triangles.array() + n;
  const auto cloud = toCloud(points);
  Search ring(std::make_shared<const MeshTopology>(2 * n, tris));
  ring.setInputCloud(cloud);
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  pcl::Indices on_mesh, in_space;
  std::vector<float> d_mesh, d_space;
  const int centre = n / 2;
  ring.radiusSearch(centre, 0.3, on_mesh, d_mesh);
  tree.radiusSearch(centre, 0.3, in_space, d_space);
  const long other_plate =
      std::count_if(in_space.begin(), in_space.end(), [&](int v) { return v >= n; });
  EXPECT_GT(other_plate, 10);
  for (const int v : on_mesh) EXPECT_LT(v, n);
  // On its own plate (convex, so every point of the ball is reachable) it finds the same set.
  std::set<int> own_plate;
  for (const int v : in_space) {
    if (v < n) own_plate.insert(v);
  }
  EXPECT_EQ(std::set<int>(on_mesh.begin(), on_mesh.end()), own_plate);
  for (std::size_t i = 0; i < on_mesh.size(); ++i) EXPECT_LE(d_mesh[i], 0.09f + 1e-6f);
  // Sorted on request, and max_nn keeps the nearest.
  ring.setSortedResults(true);
  ring.radiusSearch(centre, 0.3, on_mesh, d_mesh, 5);
  ASSERT_EQ(on_mesh.size(), 5u);
  EXPECT_TRUE(std::is_sorted(d_mesh.begin(), d_mesh.end()));
  EXPECT_EQ(on_mesh[0], centre);
}

TEST(MeshRingSearch, PCLNormalEstimationRunsOnItUnchanged) {
  SurfaceSample torus = makeTorus({48, 0.0, 1});
  const auto cloud = toCloud(torus.points);
  auto search = std::make_shared<Search>(topologyPtrOf(torus));
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> pcl_estimator;
  pcl_estimator.setInputCloud(cloud);
  pcl_estimator.setSearchMethod(search);
  pcl_estimator.setKSearch(7);  // the vertex and its 1-ring on this valence-6 grid
  pcl::PointCloud<pcl::Normal> normals;
  pcl_estimator.compute(normals);
  ASSERT_EQ(normals.size(), cloud->size());
  const AngleErrors e = angleErrors(normalsOf(normals), torus.normals, SignMode::Unsigned);
  EXPECT_EQ(e.invalid, 0);
  EXPECT_LT(e.max, 2.0);

  // The OpenMP variant, with concurrent queries, gives the same normals.
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> parallel(2);
  parallel.setInputCloud(cloud);
  parallel.setSearchMethod(search);
  parallel.setKSearch(7);
  pcl::PointCloud<pcl::Normal> parallel_normals;
  parallel.compute(parallel_normals);
  const AngleErrors difference =
      angleErrors(normalsOf(parallel_normals), normalsOf(normals), SignMode::Unsigned);
  ASSERT_EQ(parallel_normals.size(), cloud->size());
  EXPECT_EQ(difference.invalid, 0) << "NaN normals from the OpenMP variant";
  EXPECT_LT(difference.max, 1e-3);
}

TEST(MeshRingSearch, NonFiniteVerticesAreNeverNeighboursAndQueriesThereFindNothing) {
  SurfaceSample plane = makePlane({8, 0.0, 1});
  Eigen::Matrix3Xd points = plane.points;
  const int centre = static_cast<int>(points.cols()) / 2;
  const int hole = plane.triangles(1, 0) == centre ? plane.triangles(2, 0) : centre + 1;
  points.col(hole).setConstant(std::numeric_limits<double>::quiet_NaN());
  Search search(topologyPtrOf(plane));
  search.setInputCloud(toCloud(points));
  pcl::Indices found;
  std::vector<float> distances;
  EXPECT_EQ(search.nearestKSearch(centre, 20, found, distances), 20);
  EXPECT_EQ(std::count(found.begin(), found.end(), hole), 0);
  for (const float d : distances) EXPECT_TRUE(std::isfinite(d));
  EXPECT_EQ(search.nearestKSearch(hole, 5, found, distances), 0);
  EXPECT_EQ(search.radiusSearch(hole, 1.0, found, distances), 0);
}

TEST(MeshRingSearch, BadQueriesAndCloudsFailClearly) {
  SurfaceSample plane = makePlane({4, 0.0, 1});
  Search search(topologyPtrOf(plane));
  EXPECT_THROW(search.setInputCloud(toCloud(plane.points.leftCols(5))), pcl::BadArgumentException);
  const auto cloud = toCloud(plane.points);
  search.setInputCloud(cloud);
  pcl::Indices found;
  std::vector<float> distances;
  EXPECT_EQ(search.nearestKSearch(pcl::PointXYZ(0, 0, 0), 3, found, distances), 0);  // not a vertex
  EXPECT_EQ(search.radiusSearch(pcl::PointXYZ(0, 0, 0), 1.0, found, distances), 0);
  EXPECT_EQ(search.nearestKSearch(-1, 3, found, distances), 0);
  EXPECT_EQ(search.nearestKSearch(static_cast<int>(cloud->size()), 3, found, distances), 0);
  pcl::PointCloud<pcl::PointXYZ> other = *cloud;  // a copy is not the searched cloud
  EXPECT_EQ(search.nearestKSearch(other, 0, 3, found, distances), 0);
  EXPECT_EQ(search.nearestKSearch(*cloud, 0, 3, found, distances), 3);
  EXPECT_THROW(Search(std::shared_ptr<const MeshTopology>()), pcl::BadArgumentException);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
