#pragma once
// The mesh file formats, each parsed from the whole file in memory. Internal to pcl_ddg_io; use
// loadMesh / saveMesh (pcl_ddg/io/mesh_io.h). Parsers throw FileFormatException on malformed or
// truncated data and never return a partial mesh.
#include <pcl/PolygonMesh.h>

#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <string_view>

#include "pcl_ddg/io/mesh_io.h"

namespace pcl_ddg {
namespace detail {

/** PLY, ascii or binary; faces from a `face` or a `tristrips` element; a `range_grid` element
 *  turns a face-less scan into an organized cloud (NaN where the grid is empty). */
pcl::PolygonMesh parsePLY(std::string_view data);
/** OFF (also COFF/NOFF/CNOFF; extra per-vertex or per-face values ignored) and binary OFF.
 *  With rows (ascii OFF whose faces all have three corners): the faces go there, not into the
 *  mesh's polygons. */
pcl::PolygonMesh parseOFF(std::string_view data, FaceRows* rows = nullptr);
/** Wavefront OBJ: `v` and `f` records (v, v/t, v//n, v/t/n, negative relative indices). */
pcl::PolygonMesh parseOBJ(std::string_view data);
/** STL, ascii or binary; identical corner coordinates are merged into one vertex. */
pcl::PolygonMesh parseSTL(std::string_view data);
/** Legacy VTK POLYDATA, ascii or binary, classic or 5.x (OFFSETS/CONNECTIVITY) cell layout;
 *  POLYGONS and TRIANGLE_STRIPS become faces, other cells and attributes are ignored. */
pcl::PolygonMesh parseVTK(std::string_view data);
/** PCD, ascii, binary or binary_compressed (padding fields "_" kept as in PCL's reader); the
 *  VIEWPOINT into sensor_pose when given; room for spare_point_bytes more per point reserved in
 *  the cloud's data (readMeshFile's). */
pcl::PolygonMesh parsePCD(std::string_view data, SensorPose* sensor_pose = nullptr,
                          std::size_t spare_point_bytes = 0);
/** How the points of a binary cloud file lie on disk, for reading it a piece at a time. */
struct BinaryCloudLayout {
  std::int64_t header_bytes = 0;  ///< the first point starts here
  std::int64_t points = 0;
  std::int64_t point_bytes = 0;  ///< one point's record
  std::uint32_t width = 0, height = 0;
  SensorPose sensor_pose;
  std::string header;  ///< the file's header text
  /** The header rewritten for a piece of `count` points: with the piece's records it is a file
   *  that parsePCD / parsePLY read as they read the whole. */
  std::string (*header_for)(const std::string& header, std::int64_t count) = nullptr;
};

/** text with every line passed through edit (the header rewriting of BinaryCloudLayout). */
std::string editLines(const std::string& text, void (*edit)(std::string& line, std::int64_t count),
                      std::int64_t count);

/** A PLY header with its vertex count set to count. */
std::string plyHeaderWithVertices(const std::string& header, std::int64_t count);

/** The layout of a PCD file whose DATA is binary (head: the file's first bytes, the whole header
 *  among them); FileFormatException for any other. */
BinaryCloudLayout pcdBinaryLayout(std::string_view head);
/** The layout of a binary PLY cloud: one vertex element of scalar properties, other elements
 *  empty (no faces) and no range grid; FileFormatException for any other. */
BinaryCloudLayout plyBinaryLayout(std::string_view head);

/** The faces are rows when given (mesh.polygons is then empty), else mesh.polygons. */
void writePLY(std::ostream& out, const pcl::PolygonMesh& mesh, PlyEncoding encoding,
              const FaceRows* rows = nullptr);
/** A cloud as a binary_compressed PCD file (padding fields left out); `out` must be seekable (the
 *  sizes before the data are written last). */
void writePCD(std::ostream& out, const pcl::PCLPointCloud2& cloud, const SensorPose& sensor_pose);
/** The header of a binary (uncompressed) PCD file of `points` points with the cloud's fields
 *  (every field, padding included, so that the records are cloud.data's rows as they are). */
std::string binaryPCDHeader(const pcl::PCLPointCloud2& cloud, std::int64_t width,
                            std::int64_t height, const SensorPose& sensor_pose);

/** A corner index from a file; anything outside 0..INT_MAX becomes -1, which MeshTopology reports
 *  as out of range. */
inline pcl::index_t cornerIndex(std::int64_t i) {
  return i < 0 || i > std::numeric_limits<pcl::index_t>::max() ? -1 : static_cast<pcl::index_t>(i);
}

/** Appends the triangles of a strip (alternating winding) to polygons, dropping the
 *  zero-area triangles that repeated indices produce; a negative index restarts the strip. */
template <typename Index>
void appendTriangleStrip(const Index* strip, std::size_t n, std::vector<pcl::Vertices>& polygons) {
  std::size_t start = 0;
  for (std::size_t i = 0; i <= n; ++i) {
    if (i < n && strip[i] >= 0) continue;
    for (std::size_t k = start; k + 2 < i; ++k) {
      const bool even = (k - start) % 2 == 0;
      const auto a = cornerIndex(strip[k]);
      const auto b = cornerIndex(strip[even ? k + 1 : k + 2]);
      const auto c = cornerIndex(strip[even ? k + 2 : k + 1]);
      if (a == b || b == c || a == c) continue;
      pcl::Vertices triangle;
      triangle.vertices = {a, b, c};
      polygons.push_back(std::move(triangle));
    }
    start = i + 1;
  }
}

}  // namespace detail
}  // namespace pcl_ddg
