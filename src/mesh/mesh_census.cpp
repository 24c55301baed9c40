// The defect census of a MeshTopology: duplicate polygons, orientability, boundary loops, Euler
// characteristic and genus (counts(); MeshReport prints them). The connectivity they read is built
// in mesh_topology.cpp.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "detail/disjoint_sets.h"
#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

void MeshTopology::countDuplicatePolygons(const PolygonList& polygons,
                                          const std::vector<int>& others_ids,
                                          const Wedges& wedges) {
  // Two polygons are duplicates when they have the same corners (as a multiset). Plain triangles,
  // nearly every polygon of a scan, are compared at their smallest corner by the other two, which
  // the wedges of that corner's row hold: a local, parallel pass. Other polygons (more corners, a
  // repeated corner) are bucketed by their smallest corner and compared by sorted corner lists.
  // Out-of-range polygons take no part (they are not faces of the mesh), nor do those with fewer
  // than three corners.
  std::int64_t duplicates = 0;
#pragma omp parallel reduction(+ : duplicates)
  {
    std::vector<std::uint64_t> keys;  // per thread, reused across rows
#pragma omp for schedule(static)
    for (int v = 0; v < num_vertices_; ++v) {
      keys.clear();
      for (int i = vt_offsets_[v]; i < vt_offsets_[v + 1]; ++i) {
        const int next = wedges.next(i), previous = wedges.previous(i);
        if (!(wedges.corner[i] & Wedges::kPlainTriangle) || next < v || previous < v) continue;
        const auto [low, high] = std::minmax(next, previous);
        keys.push_back(static_cast<std::uint64_t>(low) << 32 | static_cast<std::uint32_t>(high));
      }
      if (keys.size() < 2) continue;
      std::sort(keys.begin(), keys.end());
      for (std::size_t j = 1; j < keys.size(); ++j) duplicates += keys[j] == keys[j - 1];
    }
  }

  std::vector<std::pair<int, int>> others;  // (smallest corner, polygon)
  others.reserve(others_ids.size());
  for (const int i : others_ids) {
    const PolygonCorners corners = polygons[i];
    others.emplace_back(*std::min_element(corners.begin(), corners.end()), i);
  }
  std::sort(others.begin(), others.end());
  std::vector<std::vector<pcl::index_t>> bucket;
  for (std::size_t begin = 0, end; begin < others.size(); begin = end) {
    for (end = begin + 1; end < others.size() && others[end].first == others[begin].first; ++end) {
    }
    if (end - begin < 2) continue;
    bucket.resize(end - begin);
    for (std::size_t j = begin; j < end; ++j) {
      auto& key = bucket[j - begin];
      const PolygonCorners corners = polygons[others[j].second];
      key.assign(corners.begin(), corners.end());
      std::sort(key.begin(), key.end());
    }
    std::sort(bucket.begin(), bucket.end());
    for (std::size_t j = 1; j < bucket.size(); ++j) duplicates += bucket[j] == bucket[j - 1];
  }
  counts_.duplicate_polygons = duplicates;
}

void MeshTopology::checkOrientability() {
  // Union-find over triangles with a parity: flipped or not relative to the set's root. A
  // manifold edge traversed the same way by both of its triangles asks for a relative flip; a
  // contradiction means the component is not orientable.
  detail::ParityDisjointSets sets(numTriangles());
  const std::vector<int>& edge_triangle_count = edgeTriangleCount();
  const Eigen::Matrix3Xi& triangle_edges = triangleEdges();
  std::vector<int> first_triangle(numEdges(), -1);
  std::vector<char> first_forward(numEdges(), 0);
  for (int t = 0; t < numTriangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int e = triangle_edges(k, t);
      if (edge_triangle_count[e] != 2) continue;
      const char forward = triangles_((k + 1) % 3, t) < triangles_((k + 2) % 3, t);
      if (first_triangle[e] < 0) {
        first_triangle[e] = t;
        first_forward[e] = forward;
        continue;
      }
      const char relative_flip = forward == first_forward[e];
      if (!sets.unite(first_triangle[e], t, relative_flip)) counts_.orientable = false;
    }
  }
}

void MeshTopology::countBoundaryLoops(const std::vector<std::pair<int, int>>& boundary_edges) {
  // Each connected piece of the boundary-edge graph holds E - V + 1 independent cycles (at least
  // one): a simple hole is one loop, two holes touching at a vertex are two.
  if (boundary_edges.empty()) return;
  detail::DisjointSets sets(num_vertices_);
  for (const auto& [a, b] : boundary_edges) sets.unite(a, b);
  std::vector<std::int64_t> edges_of_root(num_vertices_, 0), vertices_of_root(num_vertices_, 0);
  for (const auto& edge : boundary_edges) ++edges_of_root[sets.find(edge.first)];
  for (int v = 0; v < num_vertices_; ++v) {
    if (isBoundary(v)) ++vertices_of_root[sets.find(v)];
  }
  for (int r = 0; r < num_vertices_; ++r) {
    if (edges_of_root[r] > 0) {
      counts_.boundary_loops +=
          std::max<std::int64_t>(1, edges_of_root[r] - vertices_of_root[r] + 1);
    }
  }
}

std::int64_t MeshTopology::eulerCharacteristic() const {
  return static_cast<std::int64_t>(num_vertices_) - counts_.unreferenced_vertices - numEdges() +
         numTriangles();
}

std::int64_t MeshTopology::genus() const {
  const bool closed_manifold = counts_.boundary_edges == 0 && counts_.nonmanifold_edges == 0 &&
                               counts_.nonmanifold_vertices == 0 && counts_.orientable;
  if (!closed_manifold || counts_.connected_components == 0) return -1;
  return (2 * counts_.connected_components - eulerCharacteristic()) / 2;
}

}  // namespace pcl_ddg
