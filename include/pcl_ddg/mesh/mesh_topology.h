#pragma once
/** \file
 * Connectivity of a polygon mesh, built once and shared by every operator.
 *
 * The input vertex numbering is kept, so per-vertex results align with the input cloud. Polygons
 * are fan-triangulated (corner 0 with every consecutive pair); triangles keep the input winding.
 * Triangle corner k faces edge k: edge k of triangle t joins corners k+1 and k+2 (mod 3).
 * Adjacency is stored in compressed rows (CSR): vertex -> sorted neighbours, vertex -> incident
 * triangles. Edge ids (the edge map: ids, ends, triangle counts, the edges of each triangle) are
 * built on the first call that asks for one: face normals, ring searches and the defect counts need
 * only the rows, and the map costs as much as the rows again.
 */
#include <pcl/PolygonMesh.h>
#include <pcl/Vertices.h>

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "pcl_ddg/mesh/polygon_list.h"

namespace pcl_ddg {

/** What to do with a polygon that names a vertex that does not exist. */
enum class OutOfRangeFacePolicy { Throw, Drop };

/** A read-only view of a contiguous run of indices (one CSR row). */
class IndexSpan {
 public:
  IndexSpan(const int* first, const int* last) : first_(first), last_(last) {}
  const int* begin() const { return first_; }
  const int* end() const { return last_; }
  int size() const { return static_cast<int>(last_ - first_); }
  bool empty() const { return first_ == last_; }
  int operator[](int i) const { return first_[i]; }

 private:
  const int* first_;
  const int* last_;
};

/** Topological defects and statistics, counted while the topology is built. */
struct TopologyCounts {
  /** polygons_by_valence[n] = number of input polygons with n corners (n = 0, 1, 2, ... ). */
  std::vector<std::int64_t> polygons_by_valence;
  std::int64_t input_polygons = 0;
  std::int64_t out_of_range_polygons = 0;  ///< dropped (policy Drop)
  std::int64_t repeated_index_polygons =
      0;                                   ///< fewer than 3 distinct corners, or a repeated corner
  std::int64_t duplicate_polygons = 0;     ///< same vertex set as an earlier polygon
  std::int64_t triangulated_polygons = 0;  ///< polygons with more than three corners
  std::int64_t boundary_edges = 0;         ///< edges of exactly one triangle
  std::int64_t boundary_loops = 0;         ///< independent cycles of boundary edges
  std::int64_t nonmanifold_edges = 0;      ///< edges of more than two triangles
  std::int64_t nonmanifold_vertices = 0;   ///< vertices whose triangles form several fans
  std::int64_t unreferenced_vertices = 0;  ///< vertices of no triangle
  std::int64_t connected_components = 0;   ///< of the triangles (unreferenced vertices excluded)
  bool orientable = true;                  ///< every component admits a consistent orientation
  bool consistently_oriented = true;       ///< every manifold edge traversed once each way
};

/** Per-vertex flags, a bit set. */
enum class VertexFlag : std::uint8_t {
  Boundary = 1,           ///< on an edge of exactly one triangle
  NonManifoldEdge = 2,    ///< on an edge of more than two triangles
  NonManifoldVertex = 4,  ///< its triangles form more than one fan (bow-tie)
  Isolated = 8,           ///< belongs to no triangle
};

class MeshTopology {
 public:
  /** Builds from a PCL mesh; the vertex count is the cloud's width x height. */
  explicit MeshTopology(const pcl::PolygonMesh& mesh,
                        OutOfRangeFacePolicy policy = OutOfRangeFacePolicy::Throw);

  /** Builds from a vertex count and polygons (indices into 0..num_vertices-1): PCL's
   *  pcl::Vertices or rows of a fixed size (polygon_list.h). */
  MeshTopology(int num_vertices, const PolygonList& polygons,
               OutOfRangeFacePolicy policy = OutOfRangeFacePolicy::Throw);

  /** Builds from a vertex count and a 3 x T triangle index matrix (or a view of T x 3 C-order
   *  ints, as NumPy holds them). */
  MeshTopology(int num_vertices, const Eigen::Ref<const Eigen::Matrix3Xi>& triangles,
               OutOfRangeFacePolicy policy = OutOfRangeFacePolicy::Throw);

  int numVertices() const { return num_vertices_; }
  int numTriangles() const { return static_cast<int>(triangles_.cols()); }
  int numEdges() const { return num_edges_; }

  /** 3 x T corner indices. */
  const Eigen::Matrix3Xi& triangles() const { return triangles_; }
  /** The input polygon triangle t comes from (sources ascend with t). */
  int triangleSource(int t) const { return triangle_source_.empty() ? t : triangle_source_[t]; }
  /** 3 x T edge ids; entry (k, t) is the edge opposite corner k. Edge ids ascend with (smaller,
   *  larger) vertex. This and the other edge-id accessors build the edge map on first use (once,
   *  thread-safe). */
  const Eigen::Matrix3Xi& triangleEdges() const { return edgeMap().triangle_edges; }
  /** 2 x E vertex pairs, first < second. */
  const Eigen::Matrix2Xi& edgeVertices() const { return edgeMap().edge_vertices; }
  /** Number of triangles on each edge (1: boundary, 2: manifold interior, >2: non-manifold). */
  const std::vector<int>& edgeTriangleCount() const { return edgeMap().triangle_count; }

  /** Sorted distinct neighbours of v. The rows are built on first use (once, thread-safe): a
   *  user of the triangles and incidences only (face-weighted normals) never pays for them. */
  IndexSpan neighbours(int v) const {
    const NeighbourRows& rows = neighbourRows();
    return row(rows.offsets, rows.neighbours, v);
  }
  /** Edge ids parallel to neighbours(v). */
  IndexSpan neighbourEdges(int v) const {
    return row(neighbourRows().offsets, edgeMap().vv_edges, v);
  }
  /** Triangles having v as a corner (a triangle repeats only if the input repeats it). */
  IndexSpan incidentTriangles(int v) const { return row(vt_offsets_, vt_triangles_, v); }
  /** The id of edge {a, b}, or -1 if no triangle has it. */
  int findEdge(int a, int b) const;

  bool hasFlag(int v, VertexFlag flag) const {
    return (vertex_flags_[v] & static_cast<std::uint8_t>(flag)) != 0;
  }
  bool isBoundary(int v) const { return hasFlag(v, VertexFlag::Boundary); }
  bool isIsolated(int v) const { return hasFlag(v, VertexFlag::Isolated); }
  /** On a non-manifold edge or a bow-tie vertex. */
  bool isNonManifold(int v) const {
    return hasFlag(v, VertexFlag::NonManifoldEdge) || hasFlag(v, VertexFlag::NonManifoldVertex);
  }
  const std::vector<std::uint8_t>& vertexFlags() const { return vertex_flags_; }

  /** Component id per vertex (0 .. components-1), -1 for an isolated vertex. */
  const std::vector<int>& vertexComponent() const { return vertex_component_; }
  const TopologyCounts& counts() const { return counts_; }

  /** V - E + T over referenced vertices, unique edges and kept triangles. */
  std::int64_t eulerCharacteristic() const;
  /** Total genus when closed, edge-manifold and orientable; -1 otherwise. */
  std::int64_t genus() const;

 private:
  static IndexSpan row(const std::vector<int>& offsets, const std::vector<int>& data, int v) {
    return {data.data() + offsets[v], data.data() + offsets[v + 1]};
  }
  void build(const PolygonList& polygons, OutOfRangeFacePolicy policy);
  /** What triangulate learns of each polygon on its one pass over them, for the later passes. */
  struct PolygonKinds {
    std::vector<char> plain;  ///< per triangle: a whole input triangle (three distinct corners)
    std::vector<int> others;  ///< polygons in range with 3+ corners that are not plain triangles
  };
  PolygonKinds triangulate(const PolygonList& polygons, OutOfRangeFacePolicy policy);
  /** Per incidence of a vertex in a triangle (parallel to vt_triangles_): the vertex's corner
   *  index plus kPlainTriangle when the triangle is a whole input polygon, and from it the
   *  triangle's next and previous corners after the vertex. One byte per incidence, not nine:
   *  the corners are read from the triangle (a scan's triangles lie near their vertices in
   *  memory), so that the build's peak holds no copy of the faces (55 MB for the bench torus).
   *  Left uninitialised until the parallel scatter writes them, so that their pages are first
   *  touched by both threads. */
  struct Wedges {
    static constexpr std::uint8_t kPlainTriangle = 4;
    const int* triangles;  ///< triangles_'s corners, three per triangle
    const int* incident;   ///< vt_triangles_
    std::unique_ptr<std::uint8_t[]> corner;
    int next(int i) const { return triangles[3 * incident[i] + ((corner[i] & 3) + 1) % 3]; }
    int previous(int i) const { return triangles[3 * incident[i] + ((corner[i] & 3) + 2) % 3]; }
  };
  Wedges buildVertexTriangles(const std::vector<char>& plain);
  /** v's sorted distinct neighbours, from its incident triangles, into ring. */
  void gatherRing(int v, std::vector<int>& ring) const;
  /** Flags and edge counts from each vertex's own wedges and ring (gathered from its wedges in a
   *  buffer per thread, not read from the neighbour rows, which may never be needed); returns
   *  the boundary edges. */
  std::vector<std::pair<int, int>> classifyVertices(const Wedges& wedges);
  void countDuplicatePolygons(const PolygonList& polygons, const std::vector<int>& others,
                              const Wedges& wedges);
  void findComponents();
  void checkOrientability();
  void countBoundaryLoops(const std::vector<std::pair<int, int>>& boundary_edges);

  struct EdgeMap {
    Eigen::Matrix3Xi triangle_edges;
    Eigen::Matrix2Xi edge_vertices;
    std::vector<int> triangle_count;
    std::vector<int> vv_edges;  ///< parallel to NeighbourRows::neighbours
  };
  /** CSR rows of each vertex's sorted distinct neighbours. */
  struct NeighbourRows {
    std::vector<int> offsets, neighbours;
  };
  /** A value built at most once, by the first caller (thread-safe), and shared by copies of the
   *  topology, which would build the same. */
  template <typename T>
  struct Lazy {
    std::once_flag once;
    std::atomic<bool> built{false};  ///< the inline check: no call once the value is there
    T value;
    template <typename Build>
    const T& get(const Build& build) {
      if (!built.load(std::memory_order_acquire)) {
        std::call_once(once, [&] {
          value = build();
          built.store(true, std::memory_order_release);
        });
      }
      return value;
    }
  };
  const NeighbourRows& neighbourRows() const {
    return neighbour_rows_->get([this] { return buildNeighbourRows(); });
  }
  /** From the incidence rows: each incident triangle offers its two other corners. */
  NeighbourRows buildNeighbourRows() const;
  const EdgeMap& edgeMap() const {
    return edge_map_->get([this] { return buildEdgeMap(); });
  }
  EdgeMap buildEdgeMap() const;

  int num_vertices_ = 0;
  Eigen::Matrix3Xi triangles_;
  std::vector<int> triangle_source_;  ///< empty when triangle t is polygon t for all t
  int num_edges_ = 0;
  std::shared_ptr<Lazy<EdgeMap>> edge_map_ = std::make_shared<Lazy<EdgeMap>>();
  std::shared_ptr<Lazy<NeighbourRows>> neighbour_rows_ = std::make_shared<Lazy<NeighbourRows>>();
  std::vector<int> vt_offsets_, vt_triangles_;
  std::vector<std::uint8_t> vertex_flags_;
  std::vector<int> vertex_component_;
  TopologyCounts counts_;
};

}  // namespace pcl_ddg
