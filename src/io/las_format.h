#pragma once
// LAS, read and written (internal to pcl_ddg_io; use loadMesh / saveMesh, pcl_ddg/io/mesh_io.h, or
// the pieces of cloud_pieces.h): parseLAS (las_read.cpp), encodeLAS and writeLAS (las_write.cpp,
// by the plan of las_plan.cpp), LasPieceWriter (las_piece_writer.cpp). They throw
// FileFormatException on malformed or truncated data and never return a partial cloud.
//
// ASPRS LAS 1.0-1.4, uncompressed, point data record formats 0-10 (LAS 1.4 R15): read into a
// cloud whose fields are the records' fields, and written back from such a cloud. No LAS library
// is packaged in Debian 12, so the layout is implemented here, every size checked against the
// bytes the file holds before anything is allocated.
//
// A file is: the public header block (227 bytes in 1.0-1.2, 235 in 1.3, 375 in 1.4), the
// variable-length records (54-byte header + up to 65,535 bytes each), the point records (fixed
// size, the format's fields then any extra bytes), and in 1.3/1.4 extended VLRs (60-byte header,
// 64-bit length) after the points. Everything is little-endian. A coordinate is the record's
// 32-bit integer X times the header's scale plus its offset, computed in double.
#include <pcl/PCLPointCloud2.h>
#include <pcl/PolygonMesh.h>

#include <Eigen/Core>

#include <memory>
#include <string>
#include <string_view>

#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/mesh_io.h"

namespace pcl_ddg {
namespace detail {

/** A LAS file read: float x y z and the records' fields in the cloud, the exact coordinates
 *  (X * scale + offset in double) and the layout (header, VLRs, Extra Bytes). */
struct LasCloud {
  pcl::PolygonMesh mesh;
  Eigen::Matrix3Xd positions;
  LasLayout layout;
};

/** LAS 1.0-1.4, uncompressed, point formats 0-10; LAZ (the compression bit set in the point
 *  format) is refused first (readMeshFile decompresses it before: laz/laz_codec.h). The cloud's
 *  data has room for spare_point_bytes more bytes per point (readMeshFile's). */
LasCloud parseLAS(std::string_view data, std::size_t spare_point_bytes = 0);

/** parseLAS's cloud as readMeshFile returns a LAS file (coordinates Double, the layout kept). */
MeshFile lasMeshFile(std::string_view data, std::size_t spare_point_bytes = 0);

/** A cloud as a LAS file: the layout of `source` (version, point format, scale, offset, VLRs and
 *  EVLRs, Extra Bytes descriptors of the fields that remain), or LAS 1.4 format 6 (7 with
 *  colours) with a scale and offset chosen for the coordinates when null. Fields that the point
 *  format has no place for become Extra Bytes dimensions; bounds and counts are recomputed. */
std::string encodeLAS(const pcl::PCLPointCloud2& cloud, const Eigen::Matrix3Xd& positions,
                      const LasLayout* source);
/** encodeLAS's bytes into the file at path, the records encoded a block at a time
 *  from the cloud's x, y, z fields: nothing the size of the file is held. */
void writeLAS(const std::string& path, const pcl::PCLPointCloud2& cloud, const LasLayout* source);

/** A LAS file written a piece of points at a time (the out-of-core path): source's layout (version,
 *  point format, scale, offset, VLRs and EVLRs; the Extra Bytes planned from the first piece's
 *  fields, which every piece must have), the header's counts and bounds written at close(). The
 *  bytes are writeLAS's for the same points at once. */
class LasPieceWriter {
 public:
  LasPieceWriter(const std::string& path, const LasLayout& source);
  ~LasPieceWriter();
  LasPieceWriter(const LasPieceWriter&) = delete;
  LasPieceWriter& operator=(const LasPieceWriter&) = delete;
  void write(const pcl::PCLPointCloud2& piece);
  void close();

 private:
  struct State;
  LasLayout source_;
  std::unique_ptr<State> state_;
};

}  // namespace detail
}  // namespace pcl_ddg
