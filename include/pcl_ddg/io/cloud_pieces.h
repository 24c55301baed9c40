#pragma once
/** \file
 * A cloud file read and written a piece at a time, for clouds larger than memory (the out-of-core
 * fit, tiling/out_of_core_fit.h) and for workers that each read their own points of a shared file
 * (the Python module's Dask runner). A piece is parsed by the same parser as the whole file would
 * be, so every value converts exactly as it does when the file is read at once.
 *
 * Read: binary PCD (uncompressed), binary PLY clouds (one vertex element, no faces), LAS 1.0-1.4
 * without EVLRs, and LAZ with a chunk table (a piece decodes the chunks that hold its points; a
 * COPC file's hierarchy EVLR is allowed). Written: binary PCD, binary PLY, or LAS in the layout of
 * a LAS input, with the header of the whole.
 */
#include <pcl/PCLPointCloud2.h>

#include <Eigen/Core>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/io/vertex_fields.h"

namespace pcl_ddg {

/** Where a cloud file's points lie and what the whole file holds. */
struct CloudFileLayout {
  std::int64_t points = 0;
  std::int64_t header_bytes = 0;  ///< the first point's record starts here
  std::int64_t point_bytes = 0;   ///< one point's record
  std::uint32_t width = 0, height = 0;
  SensorPose sensor_pose;  ///< a PCD's VIEWPOINT
};

/** Points [first, first + count) of a file. */
struct CloudPiece {
  pcl::PCLPointCloud2 cloud;   ///< every field as the file stores it (LAS: x, y, z as FLOAT32)
  Eigen::Matrix3Xd positions;  ///< the exact coordinates (LAS: X * scale + offset), NaN kept
  FieldPrecision coordinate_precision = FieldPrecision::Float;  ///< as MeshFile's
};

class CloudPieceReader {
 public:
  /** Reads the header; FileFormatException for a file that cannot be read in pieces (text or
   *  compressed encodings, meshes, EVLRs) or that is shorter than its points. */
  explicit CloudPieceReader(const std::string& path);
  ~CloudPieceReader();
  CloudPieceReader(const CloudPieceReader&) = delete;
  CloudPieceReader& operator=(const CloudPieceReader&) = delete;

  const CloudFileLayout& layout() const;
  /** A LAS file's layout (version, point format, scale, offset, VLRs); null for other formats. */
  const std::shared_ptr<const LasLayout>& lasLayout() const;
  /** pcl::BadArgumentException when the range is not in the file. */
  CloudPiece read(std::int64_t first, std::int64_t count);
  /** A LAZ file's chunks as (first point, points), in file order (a COPC file's: its nodes);
   *  empty for other files. A piece within a chunk decodes that chunk only. */
  std::vector<std::pair<std::int64_t, std::int64_t>> lazChunks() const;

 private:
  struct Format;
  /** The file's bytes [offset, offset + count); FileFormatException when it holds fewer. */
  std::string readBytes(std::uint64_t offset, std::uint64_t count);
  /** A LAZ file's records of points [first, first + count), from the chunks that hold them. */
  std::string lazRecords(std::int64_t first, std::int64_t count);
  std::string path_;
  std::ifstream in_;
  CloudFileLayout layout_;
  std::unique_ptr<Format> format_;
  std::shared_ptr<const LasLayout> las_;
};

/** Writes a cloud of `points` points a piece at a time into `path` (the caller's temporary file:
 *  see atomic_file.h) in `format` ("ply", "pcd", "las" or "laz"), as saveMesh writes it: binary
 *  PLY, binary PCD (colours in the format's layout, no padding fields), or LAS in the layout `las`
 *  (required for "las" and "laz": a LAS input's, whose scale and offset hold the points); LAZ is
 *  the LAS file, written beside `path` and compressed into it at close(), a chunk at a time.
 *  The first piece's fields make the header; every piece must have them. */
class CloudPieceWriter {
 public:
  CloudPieceWriter(const std::string& path, const std::string& format, std::int64_t points,
                   std::uint32_t width, std::uint32_t height, const SensorPose& sensor_pose,
                   const std::shared_ptr<const LasLayout>& las = nullptr);
  ~CloudPieceWriter();
  CloudPieceWriter(const CloudPieceWriter&) = delete;
  CloudPieceWriter& operator=(const CloudPieceWriter&) = delete;
  void write(pcl::PCLPointCloud2& piece);
  /** Flushes and closes; FileFormatException when the output could not be written. */
  void close();

 private:
  struct Las;
  bool ply_;
  std::unique_ptr<Las> las_;  ///< set for a LAS output
  std::int64_t points_;
  std::uint32_t width_, height_;
  SensorPose sensor_pose_;
  std::ofstream out_;
  bool first_ = true;
  std::vector<pcl::PCLPointField> fields_;  ///< the first piece's
  std::uint32_t point_step_ = 0;
};

}  // namespace pcl_ddg
