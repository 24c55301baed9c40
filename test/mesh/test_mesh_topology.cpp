// MeshTopology on hand-made dirty meshes (each defect alone) and on analytic meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>

#include "analytic_surfaces.h"
#include "detail/disjoint_sets.h"  // internal: the union-find under the orientation check
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

// Two triangles sharing edge 1-2: a unit square split along its diagonal.
const std::vector<std::vector<int>> kSquare = {{0, 1, 2}, {0, 2, 3}};

Eigen::Matrix3Xd gridPoints(int n) {
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) << i % 4, i / 4, 0.1 * i;
  return p;
}

MeshTopology topologyOf(int num_vertices, const std::vector<std::vector<int>>& polygons,
                        OutOfRangeFacePolicy policy = OutOfRangeFacePolicy::Throw) {
  return MeshTopology(makeMesh(gridPoints(num_vertices), polygons), policy);
}

TEST(MeshTopology, EmptyMeshThrows) {
  pcl::PolygonMesh empty;
  EXPECT_THROW(MeshTopology{empty}, InvalidMeshException);
}

TEST(MeshTopology, OutOfRangeIndexThrowsNamingFaceAndCount) {
  try {
    topologyOf(4, {{0, 1, 2}, {0, 2, 7}, {0, 9, 1}});
    FAIL() << "no exception";
  } catch (const InvalidMeshException& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("face 1"), std::string::npos) << what;
    EXPECT_NE(what.find("vertex 7"), std::string::npos) << what;
    EXPECT_NE(what.find("2 faces out of range"), std::string::npos) << what;
  }
}

TEST(MeshTopology, NegativeIndexIsOutOfRange) {
  EXPECT_THROW(MeshTopology(4, Eigen::Matrix3Xi(Eigen::Vector3i(0, 1, -1))), InvalidMeshException);
}

TEST(MeshTopology, OutOfRangeFacesCanBeDroppedAndCounted) {
  const MeshTopology t = topologyOf(4, {{0, 1, 2}, {0, 2, 7}}, OutOfRangeFacePolicy::Drop);
  EXPECT_EQ(t.numTriangles(), 1);
  EXPECT_EQ(t.counts().out_of_range_polygons, 1);
  EXPECT_EQ(t.triangleSource(0), 0);
}

TEST(MeshTopology, SquareAdjacency) {
  const MeshTopology t = topologyOf(4, kSquare);
  EXPECT_EQ(t.numEdges(), 5);
  EXPECT_EQ(t.neighbours(0).size(), 3);
  EXPECT_EQ(t.neighbours(1).size(), 2);
  EXPECT_EQ(t.incidentTriangles(0).size(), 2);
  EXPECT_EQ(t.counts().boundary_edges, 4);
  EXPECT_EQ(t.counts().boundary_loops, 1);
  EXPECT_EQ(t.eulerCharacteristic(), 1);
  EXPECT_EQ(t.edgeTriangleCount()[t.findEdge(2, 0)], 2);
  EXPECT_EQ(t.findEdge(1, 3), -1);
  for (int v = 0; v < 4; ++v) EXPECT_TRUE(t.isBoundary(v));
  // Edge k of a triangle is opposite corner k.
  for (int k = 0; k < 3; ++k) {
    const int e = t.triangleEdges()(k, 0);
    const int a = t.edgeVertices()(0, e), b = t.edgeVertices()(1, e);
    EXPECT_NE(a, t.triangles()(k, 0));
    EXPECT_NE(b, t.triangles()(k, 0));
  }
}

TEST(MeshTopology, RepeatedIndexFaceIsCountedAndDropped) {
  const MeshTopology t = topologyOf(4, {{0, 1, 2}, {0, 0, 3}, {1, 2}});
  EXPECT_EQ(t.counts().repeated_index_polygons, 2);
  EXPECT_EQ(t.numTriangles(), 1);
}

TEST(MeshTopology, BowTieVertexIsNonManifold) {
  // Two triangles touching only at vertex 2.
  const MeshTopology t = topologyOf(5, {{0, 1, 2}, {2, 3, 4}});
  EXPECT_EQ(t.counts().nonmanifold_vertices, 1);
  EXPECT_TRUE(t.hasFlag(2, VertexFlag::NonManifoldVertex));
  EXPECT_FALSE(t.hasFlag(0, VertexFlag::NonManifoldVertex));
  EXPECT_EQ(t.counts().boundary_loops, 2);
  EXPECT_EQ(t.counts().connected_components, 1);
}

TEST(MeshTopology, ThreeFacesOnOneEdgeAreNonManifold) {
  const MeshTopology t = topologyOf(5, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  EXPECT_EQ(t.counts().nonmanifold_edges, 1);
  EXPECT_EQ(t.edgeTriangleCount()[t.findEdge(0, 1)], 3);
  EXPECT_TRUE(t.hasFlag(0, VertexFlag::NonManifoldEdge));
  EXPECT_TRUE(t.isNonManifold(1));
  EXPECT_FALSE(t.isNonManifold(2));
}

TEST(MeshTopology, DuplicateFaceIsCountedAndKept) {
  const MeshTopology t = topologyOf(4, {{0, 1, 2}, {1, 2, 0}, {0, 2, 3}});
  EXPECT_EQ(t.counts().duplicate_polygons, 1);
  EXPECT_EQ(t.numTriangles(), 3);
}

// Random polygon soups with every kind of overlap (the same corners in another order or winding,
// repeated corners, quads, shared and non-manifold edges) against counts made by brute force
// from the definitions: duplicates are polygons whose corner multiset appeared before; an edge is
// non-manifold on more than two triangles; the mesh is consistently oriented when every edge of
// two triangles is run once in each direction.
TEST(MeshTopology, CountsMatchBruteForceOnRandomPolygonSoups) {
  std::mt19937 random(11);
  for (int trial = 0; trial < 200; ++trial) {
    const int num_vertices = 4 + trial % 9;
    std::uniform_int_distribution<int> vertex(0, num_vertices - 1), size(3, 5), coin(0, 3);
    std::vector<std::vector<int>> polygons;
    for (int p = 0; p < 12; ++p) {
      if (!polygons.empty() && coin(random) == 0) {  // an earlier polygon, rotated or reversed
        std::vector<int> copy =
            polygons[std::uniform_int_distribution<std::size_t>(0, polygons.size() - 1)(random)];
        std::rotate(copy.begin(), copy.begin() + 1, copy.end());
        if (coin(random) < 2) std::reverse(copy.begin(), copy.end());
        polygons.push_back(copy);
        continue;
      }
      std::vector<int> corners(static_cast<std::size_t>(size(random) == 5 ? 4 : 3));
      for (int& c : corners) c = vertex(random);
      polygons.push_back(corners);
    }
    const MeshTopology t = topologyOf(num_vertices, polygons);

    std::set<std::vector<int>> seen;
    std::int64_t duplicates = 0;
    std::map<std::pair<int, int>, int> directed;  // triangle sides, in their direction
    for (const auto& polygon : polygons) {
      std::vector<int> key = polygon;
      std::sort(key.begin(), key.end());
      duplicates += !seen.insert(key).second;
    }
    for (int f = 0; f < t.numTriangles(); ++f) {
      for (int k = 0; k < 3; ++k) ++directed[{t.triangles()(k, f), t.triangles()((k + 1) % 3, f)}];
    }
    std::int64_t nonmanifold = 0;
    bool consistent = true;
    for (const auto& [side, count] : directed) {
      if (side.first > side.second) continue;
      const auto reverse = directed.find({side.second, side.first});
      const int backward = reverse == directed.end() ? 0 : reverse->second;
      nonmanifold += count + backward > 2;
      if (count + backward == 2 && count != 1) consistent = false;
    }
    for (const auto& [side, count] : directed) {  // edges run only backwards
      if (side.first > side.second && directed.count({side.second, side.first}) == 0) {
        nonmanifold += count > 2;
        if (count == 2) consistent = false;
      }
    }
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_EQ(t.counts().duplicate_polygons, duplicates);
    EXPECT_EQ(t.counts().nonmanifold_edges, nonmanifold);
    EXPECT_EQ(t.counts().consistently_oriented, consistent);
  }
}

TEST(MeshTopology, TriangleSourcesNameThePolygons) {
  const MeshTopology plain = topologyOf(4, {{0, 1, 2}, {0, 2, 3}});
  EXPECT_EQ(plain.triangleSource(0), 0);
  EXPECT_EQ(plain.triangleSource(1), 1);
  // As many triangles as polygons, but polygon 0 dropped and polygon 1 split in two.
  const MeshTopology split = topologyOf(4, {{0, 1, 9}, {0, 1, 2, 3}}, OutOfRangeFacePolicy::Drop);
  ASSERT_EQ(split.numTriangles(), 2);
  EXPECT_EQ(split.triangleSource(0), 1);
  EXPECT_EQ(split.triangleSource(1), 1);
}

TEST(MeshTopology, QuadAndPentagonAreFanTriangulated) {
  const MeshTopology t = topologyOf(9, {{0, 1, 2, 3}, {4, 5, 6, 7, 8}});
  EXPECT_EQ(t.numTriangles(), 2 + 3);
  EXPECT_EQ(t.counts().triangulated_polygons, 2);
  EXPECT_EQ(t.counts().polygons_by_valence[4], 1);
  EXPECT_EQ(t.counts().polygons_by_valence[5], 1);
  EXPECT_EQ(t.triangleSource(4), 1);
  EXPECT_EQ(t.eulerCharacteristic(), 2);  // two discs
  EXPECT_EQ(t.counts().connected_components, 2);
  // Fan from corner 0 keeps the winding: (4,5,6), (4,6,7), (4,7,8).
  EXPECT_EQ(t.triangles().col(3), Eigen::Vector3i(4, 6, 7));
}

TEST(MeshTopology, IsolatedVertexIsFlaggedAndNotAComponent) {
  const MeshTopology t = topologyOf(5, kSquare);
  EXPECT_TRUE(t.isIsolated(4));
  EXPECT_EQ(t.counts().unreferenced_vertices, 1);
  EXPECT_EQ(t.counts().connected_components, 1);
  EXPECT_EQ(t.vertexComponent()[4], -1);
  EXPECT_EQ(t.neighbours(4).size(), 0);
}

TEST(MeshTopology, TwoComponents) {
  const MeshTopology t = topologyOf(6, {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(t.counts().connected_components, 2);
  EXPECT_NE(t.vertexComponent()[0], t.vertexComponent()[3]);
  EXPECT_EQ(t.vertexComponent()[0], t.vertexComponent()[2]);
}

TEST(MeshTopology, InconsistentWindingIsDetectedButOrientable) {
  const MeshTopology t = topologyOf(4, {{0, 1, 2}, {0, 3, 2}});
  EXPECT_FALSE(t.counts().consistently_oriented);
  EXPECT_TRUE(t.counts().orientable);
}

TEST(MeshTopology, MoebiusStripIsNotOrientable) {
  // A strip of 6 quads closed with a half twist.
  const int n = 6;
  std::vector<std::vector<int>> faces;
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * i + 1;
    const bool last = i == n - 1;
    // The last quad closes the strip with a half twist: top meets bottom.
    const int c = last ? 0 : 2 * i + 3, d = last ? 1 : 2 * i + 2;
    faces.push_back({a, b, c});
    faces.push_back({a, c, d});
  }
  const MeshTopology t = topologyOf(2 * n, faces);
  EXPECT_FALSE(t.counts().orientable);
  EXPECT_EQ(t.genus(), -1);
  EXPECT_EQ(t.eulerCharacteristic(), 0);
  EXPECT_EQ(t.counts().boundary_loops, 1);  // the Moebius strip has one boundary circle
}

TEST(MeshTopology, ClosedSurfacesHaveTheirGenus) {
  const SurfaceSample sphere = makeIcosphere(2);
  EXPECT_EQ(MeshTopology(static_cast<int>(sphere.points.cols()), sphere.triangles).genus(), 0);
  const SurfaceSample torus = makeTorus({24, 0.0, 1});
  EXPECT_EQ(MeshTopology(static_cast<int>(torus.points.cols()), torus.triangles).genus(), 1);
}

TEST(MeshTopology, CylinderHasTwoBoundaryLoops) {
  const SurfaceSample cylinder = makeCylinder({24, 0.0, 1});
  const MeshTopology t(static_cast<int>(cylinder.points.cols()), cylinder.triangles);
  EXPECT_EQ(t.counts().boundary_loops, 2);
  EXPECT_EQ(t.counts().boundary_edges, 2 * 24);
}

TEST(MeshTopology, NeighbourRowsAreSortedSymmetricAndMatchEdges) {
  const SurfaceSample torus = makeTorus({20, 0.1, 2});
  const MeshTopology t(static_cast<int>(torus.points.cols()), torus.triangles);
  for (int v = 0; v < t.numVertices(); ++v) {
    const IndexSpan row = t.neighbours(v);
    EXPECT_EQ(row.size(), 6);  // regular grid triangulation of a torus
    for (int i = 0; i < row.size(); ++i) {
      if (i) ASSERT_LT(row[i - 1], row[i]);
      ASSERT_GE(t.findEdge(row[i], v), 0);
      const int e = t.neighbourEdges(v)[i];
      ASSERT_EQ(std::min(v, row[i]), t.edgeVertices()(0, e));
      ASSERT_EQ(std::max(v, row[i]), t.edgeVertices()(1, e));
    }
  }
  EXPECT_EQ(t.numEdges(), 3 * t.numVertices());
}

// The neighbour rows are built on first use: asked for first by many threads at once, and by a
// copy made before, they are the rows a brute force finds (each triangle's other two corners).
TEST(MeshTopology, NeighbourRowsBuiltOnFirstUseAreTheBruteForceRows) {
  const SurfaceSample sphere = makeIcosphere(4);
  const int n = static_cast<int>(sphere.points.cols());
  std::vector<std::set<int>> expected(n);
  for (Eigen::Index t = 0; t < sphere.triangles.cols(); ++t)
    for (int k = 0; k < 3; ++k)
      for (int j = 1; j < 3; ++j)
        expected[sphere.triangles(k, t)].insert(sphere.triangles((k + j) % 3, t));
  const MeshTopology topology(n, sphere.triangles);
  const MeshTopology copy = topology;
  EXPECT_EQ(topology.numEdges(), sphere.triangles.cols() * 3 / 2);  // counted without the rows
  std::vector<std::vector<int>> rows(n);
#pragma omp parallel for schedule(dynamic, 1)
  for (int v = 0; v < n; ++v) {
    const IndexSpan row = topology.neighbours(v);
    rows[v].assign(row.begin(), row.end());
  }
  for (int v = 0; v < n; ++v) {
    ASSERT_EQ(rows[v], std::vector<int>(expected[v].begin(), expected[v].end())) << v;
    const IndexSpan row = copy.neighbours(v);
    ASSERT_EQ(row.begin(), topology.neighbours(v).begin()) << v;  // the same rows, built once
  }
}

// The orientation union-find must stay linear on chains (a long strip unites each triangle with
// the previous one): counted in parent links followed, not by a clock. Without path compression
// and union by size the strip below takes n^2 / 2 = 5e11 steps.
TEST(MeshTopology, OrientationUnionFindIsLinearOnALongChain) {
  const int n = 1000000;
  for (const bool reversed : {false, true}) {
    detail::ParityDisjointSets sets(n);
    for (int i = 1; i < n; ++i) {
      const int t = reversed ? n - 1 - i : i;
      ASSERT_TRUE(sets.unite(reversed ? t + 1 : t - 1, t, static_cast<char>(i % 2)));
    }
    EXPECT_LE(sets.steps(), 4 * static_cast<std::int64_t>(n)) << "reversed " << reversed;
    // Parities compose along the chain: element i relative to element 0.
    const auto root = sets.find(reversed ? n - 1 : 0);
    char expected = 0;
    for (int i = 1; i < n; i += 99991) {
      expected = 0;
      for (int j = 1; j <= i; ++j) expected ^= static_cast<char>(j % 2);
      const auto r = sets.find(reversed ? n - 1 - i : i);
      EXPECT_EQ(r.root, root.root);
      EXPECT_EQ(r.parity ^ root.parity, expected) << i;
    }
  }
}

TEST(MeshTopology, AMillionTriangleStripIsOneOrientedDisk) {
  const int triangles = 1000000;
  Eigen::Matrix3Xi faces(3, triangles);
  for (int t = 0; t < triangles; ++t) {
    if (t % 2 == 0) {
      faces.col(t) << t, t + 1, t + 2;
    } else {
      faces.col(t) << t + 1, t, t + 2;
    }
  }
  const MeshTopology strip(triangles + 2, faces);
  EXPECT_TRUE(strip.counts().orientable);
  EXPECT_TRUE(strip.counts().consistently_oriented);
  EXPECT_EQ(strip.counts().boundary_loops, 1);
  EXPECT_EQ(strip.counts().connected_components, 1);
  EXPECT_EQ(strip.eulerCharacteristic(), 1);
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
