#include "pcl_ddg/mesh/mesh_topology.h"

#include <algorithm>
#include <numeric>
#include <sstream>

#include "disjoint_sets.h"
#include "pcl_ddg/exceptions.h"
#include "vertex_ranges.h"

namespace pcl_ddg {
namespace {

std::vector<pcl::Vertices> trianglesAsPolygons(const Eigen::Matrix3Xi& triangles) {
  std::vector<pcl::Vertices> polygons(triangles.cols());
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    for (int k = 0; k < 3; ++k) {
      polygons[t].vertices.push_back(triangles(k, t));
    }
  }
  return polygons;
}

bool isPlainTriangle(const pcl::Indices& corners) {
  return corners.size() == 3 && corners[0] != corners[1] && corners[1] != corners[2] &&
         corners[0] != corners[2];
}

bool hasRepeatedCorner(const pcl::Indices& corners) {
  for (std::size_t i = 0; i < corners.size(); ++i) {
    for (std::size_t j = i + 1; j < corners.size(); ++j) {
      if (corners[i] == corners[j]) return true;
    }
  }
  return false;
}

}  // namespace

MeshTopology::MeshTopology(const pcl::PolygonMesh& mesh, OutOfRangeFacePolicy policy)
    : num_vertices_(static_cast<int>(mesh.cloud.width * mesh.cloud.height)) {
  build(mesh.polygons, policy);
}

MeshTopology::MeshTopology(int num_vertices, const std::vector<pcl::Vertices>& polygons,
                           OutOfRangeFacePolicy policy)
    : num_vertices_(num_vertices) {
  build(polygons, policy);
}

MeshTopology::MeshTopology(int num_vertices, const Eigen::Matrix3Xi& triangles,
                           OutOfRangeFacePolicy policy)
    : num_vertices_(num_vertices) {
  build(trianglesAsPolygons(triangles), policy);
}

void MeshTopology::build(const std::vector<pcl::Vertices>& polygons, OutOfRangeFacePolicy policy) {
  if (num_vertices_ <= 0) throw InvalidMeshException("mesh has no vertices");
  triangulate(polygons, policy);
  {
    const Wedges wedges = buildVertexTriangles(polygons);
    buildVertexNeighbours(wedges);
    buildEdges(wedges);
    classifyEdgesAndVertices();
    findBowTieVertices(wedges);
    countDuplicatePolygons(polygons, wedges);
  }
  findComponents();
  // A consistently oriented mesh is orientable; only an inconsistent one needs the search.
  if (!counts_.consistently_oriented) checkOrientability();
  countBoundaryLoops();
}

void MeshTopology::triangulate(const std::vector<pcl::Vertices>& polygons,
                               OutOfRangeFacePolicy policy) {
  auto invalid = [&](pcl::index_t i) { return i < 0 || i >= num_vertices_; };
  auto out_of_range = [&](const pcl::Vertices& p) {
    return std::any_of(p.vertices.begin(), p.vertices.end(), invalid);
  };
  std::int64_t first_bad = -1;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    if (!out_of_range(polygons[i])) continue;
    if (first_bad < 0) first_bad = static_cast<std::int64_t>(i);
    ++counts_.out_of_range_polygons;
  }
  if (first_bad >= 0 && policy == OutOfRangeFacePolicy::Throw) {
    const auto& corners = polygons[first_bad].vertices;
    const auto bad = *std::find_if(corners.begin(), corners.end(), invalid);
    std::ostringstream msg;
    msg << "face " << first_bad << " refers to vertex " << bad << " but the mesh has "
        << num_vertices_ << " vertices (" << counts_.out_of_range_polygons
        << " faces out of range)";
    throw InvalidMeshException(msg.str());
  }

  counts_.input_polygons = static_cast<std::int64_t>(polygons.size());
  std::size_t num_triangles = 0;
  for (const auto& p : polygons) {
    const std::size_t n = p.vertices.size();
    if (counts_.polygons_by_valence.size() <= n) counts_.polygons_by_valence.resize(n + 1, 0);
    ++counts_.polygons_by_valence[n];
    if (n >= 3) num_triangles += n - 2;
  }

  triangles_.resize(3, static_cast<Eigen::Index>(num_triangles));
  triangle_source_.clear();
  triangle_source_.reserve(num_triangles);
  Eigen::Index t = 0;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const auto& c = polygons[i].vertices;
    if (first_bad >= 0 && out_of_range(polygons[i])) continue;
    if (c.size() < 3 || hasRepeatedCorner(c)) ++counts_.repeated_index_polygons;
    if (c.size() > 3) ++counts_.triangulated_polygons;
    for (std::size_t k = 1; k + 1 < c.size(); ++k) {
      if (c[0] == c[k] || c[k] == c[k + 1] || c[0] == c[k + 1]) continue;
      triangles_.col(t++) << c[0], c[k], c[k + 1];
      triangle_source_.push_back(static_cast<int>(i));
    }
  }
  triangles_.conservativeResize(3, t);
  // Every polygon one triangle, in order: the source of triangle t is t, not worth 4 bytes each.
  bool identity = static_cast<std::size_t>(t) == polygons.size();
  for (Eigen::Index i = 0; identity && i < t; ++i) identity = triangle_source_[i] == i;
  if (identity) std::vector<int>().swap(triangle_source_);
}

void MeshTopology::countDuplicatePolygons(const std::vector<pcl::Vertices>& polygons,
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
        const int next = wedges.next[i], previous = wedges.previous[i];
        if (!(wedges.corner[i] & Wedges::kPlainTriangle) || next < v || previous < v) continue;
        const auto [low, high] = std::minmax(next, previous);
        keys.push_back(static_cast<std::uint64_t>(low) << 32 | static_cast<std::uint32_t>(high));
      }
      if (keys.size() < 2) continue;
      std::sort(keys.begin(), keys.end());
      for (std::size_t j = 1; j < keys.size(); ++j) duplicates += keys[j] == keys[j - 1];
    }
  }

  const auto valid = [&](const pcl::Vertices& p) {
    return p.vertices.size() >= 3 &&
           std::all_of(p.vertices.begin(), p.vertices.end(),
                       [&](pcl::index_t i) { return i >= 0 && i < num_vertices_; });
  };
  std::vector<std::pair<int, int>> others;  // (smallest corner, polygon)
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const pcl::Indices& corners = polygons[i].vertices;
    if (isPlainTriangle(corners) || !valid(polygons[i])) continue;
    others.emplace_back(*std::min_element(corners.begin(), corners.end()), static_cast<int>(i));
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
      const pcl::Indices& corners = polygons[others[j].second].vertices;
      key.assign(corners.begin(), corners.end());
      std::sort(key.begin(), key.end());
    }
    std::sort(bucket.begin(), bucket.end());
    for (std::size_t j = 1; j < bucket.size(); ++j) duplicates += bucket[j] == bucket[j - 1];
  }
  counts_.duplicate_polygons = duplicates;
}

MeshTopology::Wedges MeshTopology::buildVertexTriangles(
    const std::vector<pcl::Vertices>& polygons) {
  const Eigen::Index num_triangles = triangles_.cols();
  vt_offsets_.assign(num_vertices_ + 1, 0);
  detail::forEachVertexRange(num_vertices_, [&](int first, int last) {
    for (Eigen::Index c = 0; c < 3 * num_triangles; ++c) {
      const int v = triangles_.data()[c];
      if (v >= first && v < last) ++vt_offsets_[v + 1];
    }
  });
  std::partial_sum(vt_offsets_.begin(), vt_offsets_.end(), vt_offsets_.begin());

  // A triangle is a plain input triangle when its source polygon is; sources ascend with t.
  std::vector<char> plain(num_triangles);
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < num_triangles; ++t) {
    plain[t] = isPlainTriangle(polygons[triangleSource(static_cast<int>(t))].vertices);
  }

  const auto incidences = static_cast<std::size_t>(vt_offsets_.back());
  vt_triangles_.resize(incidences);
  Wedges wedges{std::unique_ptr<int[]>(new int[incidences]),
                std::unique_ptr<int[]>(new int[incidences]),
                std::unique_ptr<std::uint8_t[]>(new std::uint8_t[incidences])};
  std::vector<int> cursor(vt_offsets_.begin(), vt_offsets_.end() - 1);
  detail::forEachVertexRange(num_vertices_, [&](int first, int last) {
    for (Eigen::Index t = 0; t < num_triangles; ++t) {
      for (int k = 0; k < 3; ++k) {
        const int v = triangles_(k, t);
        if (v < first || v >= last) continue;
        const int at = cursor[v]++;
        vt_triangles_[at] = static_cast<int>(t);
        wedges.next[at] = triangles_((k + 1) % 3, t);
        wedges.previous[at] = triangles_((k + 2) % 3, t);
        wedges.corner[at] = static_cast<std::uint8_t>(k | (plain[t] ? Wedges::kPlainTriangle : 0));
      }
    }
  });
  return wedges;
}

void MeshTopology::buildVertexNeighbours(const Wedges& wedges) {
  // Each incident triangle offers two neighbours; gather them into a row of twice the triangle
  // count, sort and deduplicate it in place, then compact the rows.
  const std::unique_ptr<int[]> scratch(
      new int[2 * vt_triangles_.size()]);  // first touched in parallel
  std::vector<int> row_size(num_vertices_, 0);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < num_vertices_; ++v) {
    int* out = scratch.get() + 2 * vt_offsets_[v];
    int n = 0;
    for (int i = vt_offsets_[v]; i < vt_offsets_[v + 1]; ++i) {
      out[n++] = wedges.next[i];
      out[n++] = wedges.previous[i];
    }
    std::sort(out, out + n);
    row_size[v] = static_cast<int>(std::unique(out, out + n) - out);
  }
  vv_offsets_.assign(num_vertices_ + 1, 0);
  for (int v = 0; v < num_vertices_; ++v) vv_offsets_[v + 1] = vv_offsets_[v] + row_size[v];
  vv_neighbours_.resize(vv_offsets_.back());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < num_vertices_; ++v) {
    const int* in = scratch.get() + 2 * vt_offsets_[v];
    std::copy(in, in + row_size[v], vv_neighbours_.begin() + vv_offsets_[v]);
  }
}

int MeshTopology::findEdge(int a, int b) const {
  const IndexSpan row_a = neighbours(a);
  const int* it = std::lower_bound(row_a.begin(), row_a.end(), b);
  if (it == row_a.end() || *it != b) return -1;
  return vv_edges_[vv_offsets_[a] + static_cast<int>(it - row_a.begin())];
}

void MeshTopology::buildEdges(const Wedges& wedges) {
  // Edge ids in order of (smaller vertex, larger vertex), from a prefix sum over each row's count
  // of larger neighbours (rows are sorted). Edge (v, w), v < w, belongs to v's row; w's row lists
  // its smaller neighbours first and in ascending order, so visiting v in ascending order and
  // appending each edge to w's row fills those entries in place (a CSR transpose, no searching).
  const auto firstLarger = [&](int v) {
    const IndexSpan row = neighbours(v);
    return static_cast<int>(std::upper_bound(row.begin(), row.end(), v) - row.begin());
  };
  std::vector<int> first_edge(num_vertices_ + 1, 0);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < num_vertices_; ++v) first_edge[v + 1] = neighbours(v).size() - firstLarger(v);
  std::partial_sum(first_edge.begin(), first_edge.end(), first_edge.begin());
  const int num_edges = first_edge.back();

  vv_edges_.resize(vv_neighbours_.size());
  edge_vertices_.resize(2, num_edges);
  std::vector<int> smaller_filled(vv_offsets_.begin(), vv_offsets_.end() - 1);
  detail::forEachVertexRange(num_vertices_, [&](int first, int last) {
    for (int v = 0; v < num_vertices_; ++v) {
      const IndexSpan row = neighbours(v);
      const int larger = first_edge[v + 1] - first_edge[v];
      for (int i = row.size() - larger; i < row.size(); ++i) {
        const int w = row[i], e = first_edge[v] + i - (row.size() - larger);
        if (v >= first && v < last) {
          vv_edges_[vv_offsets_[v] + i] = e;
          edge_vertices_.col(e) << v, w;
        }
        if (w >= first && w < last) vv_edges_[smaller_filled[w]++] = e;
      }
    }
  });

  // Sides (v, next) and (v, previous) of each triangle at v, written when v is their smaller end:
  // side (v, next) is opposite corner k + 2 and runs forward (from the smaller vertex), side
  // (v, previous) is opposite corner k + 1 and runs backward. Consistently oriented: every edge of
  // two triangles is run once each way.
  triangle_edges_.resize(3, triangles_.cols());
  edge_triangle_count_.assign(num_edges, 0);
  std::vector<std::uint8_t> forward_sides(num_edges, 0);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < num_vertices_; ++v) {
    const IndexSpan row = neighbours(v);
    const auto edgeTo = [&](int w) {
      const int at = static_cast<int>(std::lower_bound(row.begin(), row.end(), w) - row.begin());
      return vv_edges_[vv_offsets_[v] + at];
    };
    for (int i = vt_offsets_[v]; i < vt_offsets_[v + 1]; ++i) {
      const int t = vt_triangles_[i], k = wedges.corner[i] & 3;
      if (wedges.next[i] > v) {
        const int e = edgeTo(wedges.next[i]);
        triangle_edges_((k + 2) % 3, t) = e;
        ++edge_triangle_count_[e];
        forward_sides[e] = static_cast<std::uint8_t>(std::min(forward_sides[e] + 1, 255));
      }
      if (wedges.previous[i] > v) {
        const int e = edgeTo(wedges.previous[i]);
        triangle_edges_((k + 1) % 3, t) = e;
        ++edge_triangle_count_[e];
      }
    }
  }
  bool consistent = true;
#pragma omp parallel for schedule(static) reduction(&& : consistent)
  for (int e = 0; e < num_edges; ++e) {
    consistent = consistent && (edge_triangle_count_[e] != 2 || forward_sides[e] == 1);
  }
  counts_.consistently_oriented = consistent;
}

void MeshTopology::classifyEdgesAndVertices() {
  vertex_flags_.assign(num_vertices_, 0);
  for (int e = 0; e < numEdges(); ++e) {
    const int count = edge_triangle_count_[e];
    VertexFlag flag;
    if (count == 1) {
      ++counts_.boundary_edges;
      flag = VertexFlag::Boundary;
    } else if (count > 2) {
      ++counts_.nonmanifold_edges;
      flag = VertexFlag::NonManifoldEdge;
    } else {
      continue;
    }
    vertex_flags_[edge_vertices_(0, e)] |= static_cast<std::uint8_t>(flag);
    vertex_flags_[edge_vertices_(1, e)] |= static_cast<std::uint8_t>(flag);
  }
  for (int v = 0; v < num_vertices_; ++v) {
    if (vt_offsets_[v] == vt_offsets_[v + 1]) {
      vertex_flags_[v] |= static_cast<std::uint8_t>(VertexFlag::Isolated);
      ++counts_.unreferenced_vertices;
    }
  }
}

void MeshTopology::findBowTieVertices(const Wedges& wedges) {
  // The triangles around v form fans: two are in one fan when they share an edge at v.
  // More than one fan means the surface is pinched at v.
  int max_valence = 0;
  for (int v = 0; v < num_vertices_; ++v) {
    max_valence = std::max(max_valence, vt_offsets_[v + 1] - vt_offsets_[v]);
  }
  std::int64_t bow_ties = 0;
#pragma omp parallel reduction(+ : bow_ties)
  {
    std::vector<int> parent(max_valence);
    std::vector<int> first_triangle_at_neighbour(max_valence * 2);
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
#pragma omp for schedule(static)
    for (int v = 0; v < num_vertices_; ++v) {
      const IndexSpan tris = incidentTriangles(v);
      const IndexSpan ring = neighbours(v);
      if (tris.size() < 2) continue;
      std::iota(parent.begin(), parent.begin() + tris.size(), 0);
      std::fill(first_triangle_at_neighbour.begin(),
                first_triangle_at_neighbour.begin() + ring.size(), -1);
      int fans = tris.size();
      for (int i = 0; i < tris.size(); ++i) {
        const int wedge = vt_offsets_[v] + i;
        for (const int w : {wedges.next[wedge], wedges.previous[wedge]}) {
          const int slot =
              static_cast<int>(std::lower_bound(ring.begin(), ring.end(), w) - ring.begin());
          int& first = first_triangle_at_neighbour[slot];
          if (first < 0) {
            first = i;
          } else {
            const int a = find(first), b = find(i);
            if (a != b) {
              parent[a] = b;
              --fans;
            }
          }
        }
      }
      if (fans > 1) {
        vertex_flags_[v] |= static_cast<std::uint8_t>(VertexFlag::NonManifoldVertex);
        ++bow_ties;
      }
    }
  }
  counts_.nonmanifold_vertices = bow_ties;
}

void MeshTopology::findComponents() {
  detail::DisjointSets sets(num_vertices_);
  for (Eigen::Index t = 0; t < triangles_.cols(); ++t) {
    sets.unite(triangles_(0, t), triangles_(1, t));
    sets.unite(triangles_(0, t), triangles_(2, t));
  }
  vertex_component_.assign(num_vertices_, -1);
  std::vector<int> component_of_root(num_vertices_, -1);
  int components = 0;
  for (int v = 0; v < num_vertices_; ++v) {
    if (isIsolated(v)) continue;
    int& id = component_of_root[sets.find(v)];
    if (id < 0) id = components++;
    vertex_component_[v] = id;
  }
  counts_.connected_components = components;
}

void MeshTopology::checkOrientability() {
  // Union-find over triangles with a parity: flipped or not relative to the set's root. A
  // manifold edge traversed the same way by both of its triangles asks for a relative flip; a
  // contradiction means the component is not orientable.
  detail::ParityDisjointSets sets(numTriangles());
  std::vector<int> first_triangle(numEdges(), -1);
  std::vector<char> first_forward(numEdges(), 0);
  for (int t = 0; t < numTriangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int e = triangle_edges_(k, t);
      if (edge_triangle_count_[e] != 2) continue;
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

void MeshTopology::countBoundaryLoops() {
  // Each connected piece of the boundary-edge graph holds E - V + 1 independent cycles (at least
  // one): a simple hole is one loop, two holes touching at a vertex are two.
  detail::DisjointSets sets(num_vertices_);
  for (int e = 0; e < numEdges(); ++e) {
    if (edge_triangle_count_[e] == 1) sets.unite(edge_vertices_(0, e), edge_vertices_(1, e));
  }
  std::vector<std::int64_t> edges_of_root(num_vertices_, 0), vertices_of_root(num_vertices_, 0);
  for (int e = 0; e < numEdges(); ++e) {
    if (edge_triangle_count_[e] == 1) ++edges_of_root[sets.find(edge_vertices_(0, e))];
  }
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
