#pragma once
/** \file
 * Everything worth knowing about a mesh before trusting numbers computed on it.
 */
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/mesh/positions_ref.h"

namespace pcl_ddg {

struct MeshReport {
  std::int64_t vertices = 0;
  std::int64_t faces = 0;      ///< polygons as stored (a triangle strip counts its triangles)
  std::int64_t triangles = 0;  ///< after fan triangulation, without repeated-corner triangles
  std::vector<std::int64_t> faces_by_valence;  ///< [n] = faces with n corners
  std::int64_t out_of_range_faces = 0;
  std::int64_t degenerate_faces = 0;  ///< repeated corner, or zero area by the relative guard
  std::int64_t zero_area_faces = 0;   ///< the zero-area part of degenerate_faces
  std::int64_t duplicate_faces = 0;
  std::int64_t triangulated_faces = 0;  ///< faces with more than three corners
  std::int64_t edges = 0;
  std::int64_t boundary_edges = 0;
  std::int64_t boundary_loops = 0;
  std::int64_t nonmanifold_edges = 0;
  std::int64_t nonmanifold_vertices = 0;
  std::int64_t unreferenced_vertices = 0;
  std::int64_t nonfinite_vertices = 0;
  std::int64_t connected_components = 0;
  std::int64_t euler_characteristic = 0;
  std::int64_t genus = -1;  ///< -1 unless closed, manifold and orientable
  bool orientable = true;
  bool consistently_oriented = true;
  double mean_edge_length = 0.0;
  BoundingBox bounding_box;

  /** One JSON object (keys as the member names, bounding box as two arrays). */
  std::string toJson() const;
  /** Human-readable lines, one fact per line. */
  std::string toText() const;
};

/** Faces all of whose triangles have zero area by the relative guard (mesh_geometry.h). */
std::int64_t countZeroAreaFaces(const MeshTopology& topology, const PositionsRef& positions);

/** Counts every defect of the mesh; positions may hold non-finite vertices (they are counted). */
MeshReport makeMeshReport(const MeshTopology& topology, const PositionsRef& positions);

}  // namespace pcl_ddg
