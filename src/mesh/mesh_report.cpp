#include "pcl_ddg/mesh/mesh_report.h"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "json_number.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {

std::int64_t countZeroAreaFaces(const MeshTopology& topology, const PositionsRef& positions) {
  // A face counts when all its triangles are degenerate; its triangles are consecutive, and it is
  // counted from its first one.
  const Eigen::Matrix3Xi& tris = topology.triangles();
  const auto source = [&topology](int t) { return topology.triangleSource(t); };
  const int num_triangles = topology.numTriangles();
  std::int64_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
  for (int t = 0; t < num_triangles; ++t) {
    if (t > 0 && source(t - 1) == source(t)) continue;
    bool all_degenerate = true;
    for (int u = t; u < num_triangles && source(u) == source(t) && all_degenerate; ++u) {
      all_degenerate = isDegenerateTriangle(positions.col(tris(0, u)), positions.col(tris(1, u)),
                                            positions.col(tris(2, u)));
    }
    count += all_degenerate;
  }
  return count;
}

MeshReport makeMeshReport(const MeshTopology& topology, const PositionsRef& positions) {
  const TopologyCounts& c = topology.counts();
  MeshReport r;
  r.vertices = topology.numVertices();
  r.faces = c.input_polygons;
  r.triangles = topology.numTriangles();
  r.faces_by_valence = c.polygons_by_valence;
  r.out_of_range_faces = c.out_of_range_polygons;
  r.zero_area_faces = countZeroAreaFaces(topology, positions);
  r.degenerate_faces = c.repeated_index_polygons + r.zero_area_faces;
  r.duplicate_faces = c.duplicate_polygons;
  r.triangulated_faces = c.triangulated_polygons;
  r.edges = topology.numEdges();
  r.boundary_edges = c.boundary_edges;
  r.boundary_loops = c.boundary_loops;
  r.nonmanifold_edges = c.nonmanifold_edges;
  r.nonmanifold_vertices = c.nonmanifold_vertices;
  r.unreferenced_vertices = c.unreferenced_vertices;
  r.nonfinite_vertices = findNonFiniteVertices(positions).count;
  r.connected_components = c.connected_components;
  r.euler_characteristic = topology.eulerCharacteristic();
  r.genus = topology.genus();
  r.orientable = c.orientable;
  r.consistently_oriented = c.consistently_oriented;
  r.mean_edge_length = meanEdgeLength(topology, positions);
  r.bounding_box = boundingBox(positions);
  return r;
}

std::string MeshReport::toJson() const {
  std::ostringstream out;
  out << "{\"vertices\": " << vertices << ", \"faces\": " << faces
      << ", \"triangles\": " << triangles << ", \"faces_by_valence\": {";
  bool first = true;
  for (std::size_t n = 0; n < faces_by_valence.size(); ++n) {
    if (faces_by_valence[n] == 0) continue;
    out << (first ? "" : ", ") << "\"" << n << "\": " << faces_by_valence[n];
    first = false;
  }
  out << "}, \"out_of_range_faces\": " << out_of_range_faces
      << ", \"degenerate_faces\": " << degenerate_faces
      << ", \"zero_area_faces\": " << zero_area_faces
      << ", \"duplicate_faces\": " << duplicate_faces
      << ", \"triangulated_faces\": " << triangulated_faces << ", \"edges\": " << edges
      << ", \"boundary_edges\": " << boundary_edges << ", \"boundary_loops\": " << boundary_loops
      << ", \"nonmanifold_edges\": " << nonmanifold_edges
      << ", \"nonmanifold_vertices\": " << nonmanifold_vertices
      << ", \"unreferenced_vertices\": " << unreferenced_vertices
      << ", \"nonfinite_vertices\": " << nonfinite_vertices
      << ", \"connected_components\": " << connected_components
      << ", \"euler_characteristic\": " << euler_characteristic << ", \"genus\": ";
  if (genus >= 0) {
    out << genus;
  } else {
    out << "null";
  }
  out << ", \"orientable\": " << (orientable ? "true" : "false")
      << ", \"consistently_oriented\": " << (consistently_oriented ? "true" : "false")
      << ", \"mean_edge_length\": " << detail::jsonNumber(mean_edge_length)
      << ", \"bounding_box_min\": " << detail::jsonArray(bounding_box.min)
      << ", \"bounding_box_max\": " << detail::jsonArray(bounding_box.max) << "}";
  return out.str();
}

std::string MeshReport::toText() const {
  std::ostringstream out;
  out << "vertices:              " << vertices << "\n";
  out << "faces:                 " << faces;
  for (std::size_t n = 0; n < faces_by_valence.size(); ++n) {
    if (faces_by_valence[n] > 0) out << "  [" << n << "-gons: " << faces_by_valence[n] << "]";
  }
  out << "\ntriangles:             " << triangles << "\n"
      << "edges:                 " << edges << "\n"
      << "out-of-range faces:    " << out_of_range_faces << "\n"
      << "degenerate faces:      " << degenerate_faces << " (zero area: " << zero_area_faces
      << ")\n"
      << "duplicate faces:       " << duplicate_faces << "\n"
      << "boundary edges:        " << boundary_edges << " in " << boundary_loops << " loops\n"
      << "non-manifold edges:    " << nonmanifold_edges << "\n"
      << "non-manifold vertices: " << nonmanifold_vertices << "\n"
      << "unreferenced vertices: " << unreferenced_vertices << "\n"
      << "non-finite vertices:   " << nonfinite_vertices << "\n"
      << "components:            " << connected_components << "\n"
      << "Euler characteristic:  " << euler_characteristic << "\n"
      << "genus:                 " << (genus >= 0 ? std::to_string(genus) : "n/a") << "\n"
      << "orientable:            " << (orientable ? "yes" : "no")
      << (consistently_oriented ? ", consistently oriented" : ", NOT consistently oriented") << "\n"
      << "mean edge length:      " << mean_edge_length << "\n"
      << "bounding box:          " << detail::textArray(bounding_box.min) << " .. "
      << detail::textArray(bounding_box.max) << "\n";
  return out.str();
}

}  // namespace pcl_ddg
