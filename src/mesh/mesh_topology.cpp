#include "pcl_ddg/mesh/mesh_topology.h"

#include <algorithm>
#include <numeric>
#include <sstream>

#include "detail/disjoint_sets.h"
#include "detail/vertex_ranges.h"
#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {
namespace {

bool hasRepeatedCorner(const PolygonCorners& corners) {
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

MeshTopology::MeshTopology(int num_vertices, const PolygonList& polygons,
                           OutOfRangeFacePolicy policy)
    : num_vertices_(num_vertices) {
  build(polygons, policy);
}

MeshTopology::MeshTopology(int num_vertices, const Eigen::Ref<const Eigen::Matrix3Xi>& triangles,
                           OutOfRangeFacePolicy policy)
    : num_vertices_(num_vertices) {
  // Rows of three corners (a column-major 3 x T matrix is row-major T x 3), read in place when
  // its columns are packed.
  const auto rows = static_cast<std::size_t>(triangles.cols());
  if (triangles.outerStride() == 3 || rows == 0) {
    build(PolygonList(triangles.data(), rows, 3), policy);
    return;
  }
  const Eigen::Matrix3Xi packed = triangles;
  build(PolygonList(packed.data(), rows, 3), policy);
}

void MeshTopology::build(const PolygonList& polygons, OutOfRangeFacePolicy policy) {
  if (num_vertices_ <= 0) throw InvalidMeshException("mesh has no vertices");
  std::vector<std::pair<int, int>> boundary_edges;
  {
    const PolygonKinds kinds = triangulate(polygons, policy);
    const Wedges wedges = buildVertexTriangles(kinds.plain);
    boundary_edges = classifyVertices(wedges);
    countDuplicatePolygons(polygons, kinds.others, wedges);
  }
  findComponents();
  // A consistently oriented mesh is orientable; only an inconsistent one needs the search (and
  // the edge map).
  if (!counts_.consistently_oriented) checkOrientability();
  countBoundaryLoops(boundary_edges);
}

MeshTopology::PolygonKinds MeshTopology::triangulate(const PolygonList& polygons,
                                                     OutOfRangeFacePolicy policy) {
  auto invalid = [&](pcl::index_t i) { return i < 0 || i >= num_vertices_; };
  auto out_of_range = [&](const PolygonCorners& p) {
    return std::any_of(p.begin(), p.end(), invalid);
  };
  std::int64_t first_bad = -1;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    if (!out_of_range(polygons[i])) continue;
    if (first_bad < 0) first_bad = static_cast<std::int64_t>(i);
    ++counts_.out_of_range_polygons;
  }
  if (first_bad >= 0 && policy == OutOfRangeFacePolicy::Throw) {
    const PolygonCorners corners = polygons[first_bad];
    const auto bad = *std::find_if(corners.begin(), corners.end(), invalid);
    std::ostringstream msg;
    msg << "face " << first_bad << " refers to vertex " << bad << " but the mesh has "
        << num_vertices_ << " vertices (" << counts_.out_of_range_polygons
        << " faces out of range)";
    throw InvalidMeshException(msg.str());
  }

  counts_.input_polygons = static_cast<std::int64_t>(polygons.size());
  std::size_t num_triangles = 0;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const std::size_t n = polygons[i].size();
    if (counts_.polygons_by_valence.size() <= n) counts_.polygons_by_valence.resize(n + 1, 0);
    ++counts_.polygons_by_valence[n];
    if (n >= 3) num_triangles += n - 2;
  }

  triangles_.resize(3, static_cast<Eigen::Index>(num_triangles));
  triangle_source_.clear();
  triangle_source_.reserve(num_triangles);
  PolygonKinds kinds;
  kinds.plain.reserve(num_triangles);
  Eigen::Index t = 0;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const PolygonCorners c = polygons[i];
    if (first_bad >= 0 && out_of_range(c)) continue;
    const bool repeated = c.size() < 3 || hasRepeatedCorner(c);
    if (repeated) ++counts_.repeated_index_polygons;
    if (c.size() > 3) ++counts_.triangulated_polygons;
    const bool plain = c.size() == 3 && !repeated;
    if (!plain && c.size() >= 3) kinds.others.push_back(static_cast<int>(i));
    for (std::size_t k = 1; k + 1 < c.size(); ++k) {
      if (c[0] == c[k] || c[k] == c[k + 1] || c[0] == c[k + 1]) continue;
      triangles_.col(t++) << c[0], c[k], c[k + 1];
      triangle_source_.push_back(static_cast<int>(i));
      kinds.plain.push_back(plain);
    }
  }
  triangles_.conservativeResize(3, t);
  // Every polygon one triangle, in order: the source of triangle t is t, not worth 4 bytes each.
  bool identity = static_cast<std::size_t>(t) == polygons.size();
  for (Eigen::Index i = 0; identity && i < t; ++i) identity = triangle_source_[i] == i;
  if (identity) std::vector<int>().swap(triangle_source_);
  return kinds;
}

MeshTopology::Wedges MeshTopology::buildVertexTriangles(const std::vector<char>& plain) {
  const Eigen::Index num_triangles = triangles_.cols();
  vt_offsets_.assign(num_vertices_ + 1, 0);
  detail::forEachVertexRange(num_vertices_, [&](int first, int last) {
    for (Eigen::Index c = 0; c < 3 * num_triangles; ++c) {
      const int v = triangles_.data()[c];
      if (v >= first && v < last) ++vt_offsets_[v + 1];
    }
  });
  std::partial_sum(vt_offsets_.begin(), vt_offsets_.end(), vt_offsets_.begin());

  const auto incidences = static_cast<std::size_t>(vt_offsets_.back());
  vt_triangles_.resize(incidences);
  Wedges wedges{triangles_.data(), vt_triangles_.data(),
                std::unique_ptr<std::uint8_t[]>(new std::uint8_t[incidences])};
  std::vector<int> cursor(vt_offsets_.begin(), vt_offsets_.end() - 1);
  detail::forEachVertexRange(num_vertices_, [&](int first, int last) {
    for (Eigen::Index t = 0; t < num_triangles; ++t) {
      for (int k = 0; k < 3; ++k) {
        const int v = triangles_(k, t);
        if (v < first || v >= last) continue;
        const int at = cursor[v]++;
        vt_triangles_[at] = static_cast<int>(t);
        wedges.corner[at] = static_cast<std::uint8_t>(k | (plain[t] ? Wedges::kPlainTriangle : 0));
      }
    }
  });
  return wedges;
}

void MeshTopology::gatherRing(int v, std::vector<int>& ring) const {
  ring.clear();
  for (const int t : incidentTriangles(v)) {
    const int k = triangles_(0, t) == v ? 0 : triangles_(1, t) == v ? 1 : 2;
    ring.push_back(triangles_((k + 1) % 3, t));
    ring.push_back(triangles_((k + 2) % 3, t));
  }
  std::sort(ring.begin(), ring.end());
  ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
}

MeshTopology::NeighbourRows MeshTopology::buildNeighbourRows() const {
  // A row is found twice, once to size the rows and once to fill them, in a buffer per thread:
  // no scratch of two ints per incidence (55 MB for the bench torus).
  NeighbourRows rows;
  rows.offsets.assign(num_vertices_ + 1, 0);
#pragma omp parallel
  {
    std::vector<int> ring;
#pragma omp for schedule(static)
    for (int v = 0; v < num_vertices_; ++v) {
      gatherRing(v, ring);
      rows.offsets[v + 1] = static_cast<int>(ring.size());
    }
  }
  std::partial_sum(rows.offsets.begin(), rows.offsets.end(), rows.offsets.begin());
  rows.neighbours.resize(rows.offsets.back());
#pragma omp parallel
  {
    std::vector<int> ring;
#pragma omp for schedule(static)
    for (int v = 0; v < num_vertices_; ++v) {
      gatherRing(v, ring);
      std::copy(ring.begin(), ring.end(), rows.neighbours.begin() + rows.offsets[v]);
    }
  }
  return rows;
}

int MeshTopology::findEdge(int a, int b) const {
  const IndexSpan row_a = neighbours(a);
  const int* it = std::lower_bound(row_a.begin(), row_a.end(), b);
  if (it == row_a.end() || *it != b) return -1;
  return edgeMap().vv_edges[neighbourRows().offsets[a] + static_cast<int>(it - row_a.begin())];
}

MeshTopology::EdgeMap MeshTopology::buildEdgeMap() const {
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

  const std::vector<int>& offsets = neighbourRows().offsets;
  EdgeMap map;
  map.vv_edges.resize(neighbourRows().neighbours.size());
  map.edge_vertices.resize(2, num_edges_);
  std::vector<int> smaller_filled(offsets.begin(), offsets.end() - 1);
  detail::forEachVertexRange(num_vertices_, [&](int first, int last) {
    for (int v = 0; v < num_vertices_; ++v) {
      const IndexSpan row = neighbours(v);
      const int larger = first_edge[v + 1] - first_edge[v];
      for (int i = row.size() - larger; i < row.size(); ++i) {
        const int w = row[i], e = first_edge[v] + i - (row.size() - larger);
        if (v >= first && v < last) {
          map.vv_edges[offsets[v] + i] = e;
          map.edge_vertices.col(e) << v, w;
        }
        if (w >= first && w < last) map.vv_edges[smaller_filled[w]++] = e;
      }
    }
  });

  // Sides (v, next) and (v, previous) of each triangle at v, written when v is their smaller end:
  // side (v, next) is opposite corner k + 2, side (v, previous) opposite corner k + 1.
  map.triangle_edges.resize(3, triangles_.cols());
  map.triangle_count.assign(num_edges_, 0);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < num_vertices_; ++v) {
    const IndexSpan row = neighbours(v);
    const auto edgeTo = [&](int w) {
      const int at = static_cast<int>(std::lower_bound(row.begin(), row.end(), w) - row.begin());
      return map.vv_edges[offsets[v] + at];
    };
    for (const int t : incidentTriangles(v)) {
      const int k = triangles_(0, t) == v ? 0 : triangles_(1, t) == v ? 1 : 2;
      const int next = triangles_((k + 1) % 3, t), previous = triangles_((k + 2) % 3, t);
      if (next > v) {
        const int e = edgeTo(next);
        map.triangle_edges((k + 2) % 3, t) = e;
        ++map.triangle_count[e];
      }
      if (previous > v) {
        const int e = edgeTo(previous);
        map.triangle_edges((k + 1) % 3, t) = e;
        ++map.triangle_count[e];
      }
    }
  }
  return map;
}

std::vector<std::pair<int, int>> MeshTopology::classifyVertices(const Wedges& wedges) {
  // Each vertex reads only its own wedges and ring and writes only its own flag, so the pass is
  // parallel without atomics. Per ring slot (neighbour w): the triangles on edge {v, w} and how
  // many of them run v -> w. An edge is counted at its smaller end; there, with two triangles, it
  // is consistently oriented when one runs each way. The triangles around v form fans: two are in
  // one fan when they share an edge at v; more than one fan means the surface is pinched at v.
  int max_valence = 0;
  for (int v = 0; v < num_vertices_; ++v) {
    max_valence = std::max(max_valence, vt_offsets_[v + 1] - vt_offsets_[v]);
  }
  vertex_flags_.assign(num_vertices_, 0);
  std::vector<std::pair<int, int>> boundary_edges;
  std::int64_t boundary = 0, nonmanifold = 0, bow_ties = 0, unreferenced = 0;
  std::int64_t edges = 0;  // each counted at its smaller end
  bool consistent = true;
#pragma omp parallel reduction(+ : boundary, nonmanifold, bow_ties, unreferenced, edges) \
    reduction(&& : consistent)
  {
    std::vector<int> ring;
    std::vector<int> parent(max_valence);
    std::vector<int> first_triangle_at_neighbour(max_valence * 2);
    std::vector<int> triangles_at_neighbour(max_valence * 2), forward_at_neighbour(max_valence * 2);
    std::vector<std::pair<int, int>> my_boundary_edges;
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
#pragma omp for schedule(static) nowait
    for (int v = 0; v < num_vertices_; ++v) {
      gatherRing(v, ring);
      edges += ring.end() - std::upper_bound(ring.begin(), ring.end(), v);
      const int valence = vt_offsets_[v + 1] - vt_offsets_[v];
      if (valence == 0) {
        vertex_flags_[v] = static_cast<std::uint8_t>(VertexFlag::Isolated);
        ++unreferenced;
        continue;
      }
      std::iota(parent.begin(), parent.begin() + valence, 0);
      std::fill_n(first_triangle_at_neighbour.begin(), ring.size(), -1);
      std::fill_n(triangles_at_neighbour.begin(), ring.size(), 0);
      std::fill_n(forward_at_neighbour.begin(), ring.size(), 0);
      int fans = valence;
      for (int i = 0; i < valence; ++i) {
        const int wedge = vt_offsets_[v] + i;
        for (const int w : {wedges.next(wedge), wedges.previous(wedge)}) {
          const int slot =
              static_cast<int>(std::lower_bound(ring.begin(), ring.end(), w) - ring.begin());
          ++triangles_at_neighbour[slot];
          forward_at_neighbour[slot] += w == wedges.next(wedge);
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
      std::uint8_t flags = 0;
      if (fans > 1) {
        flags |= static_cast<std::uint8_t>(VertexFlag::NonManifoldVertex);
        ++bow_ties;
      }
      for (int slot = 0; slot < static_cast<int>(ring.size()); ++slot) {
        const int count = triangles_at_neighbour[slot];
        const bool smaller_end = ring[slot] > v;
        if (count == 1) {
          flags |= static_cast<std::uint8_t>(VertexFlag::Boundary);
          if (smaller_end) my_boundary_edges.emplace_back(v, ring[slot]);
        } else if (count > 2) {
          flags |= static_cast<std::uint8_t>(VertexFlag::NonManifoldEdge);
          nonmanifold += smaller_end;
        } else if (smaller_end) {
          consistent = consistent && forward_at_neighbour[slot] == 1;
        }
      }
      vertex_flags_[v] = flags;
    }
    boundary += static_cast<std::int64_t>(my_boundary_edges.size());
#pragma omp critical(pcl_ddg_boundary_edges)
    boundary_edges.insert(boundary_edges.end(), my_boundary_edges.begin(), my_boundary_edges.end());
  }
  num_edges_ = static_cast<int>(edges);
  counts_.boundary_edges = boundary;
  counts_.nonmanifold_edges = nonmanifold;
  counts_.nonmanifold_vertices = bow_ties;
  counts_.unreferenced_vertices = unreferenced;
  counts_.consistently_oriented = consistent;
  return boundary_edges;
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

}  // namespace pcl_ddg
