#pragma once
/** \file
 * COPC (Cloud Optimized Point Cloud, copc.io, version 1.0): a LAZ 1.4 file of point format 6, 7
 * or 8 whose chunks of variable size are the nodes of an octree, indexed by a hierarchy, so that
 * a reader fetches only the byte ranges of the nodes it wants.
 *
 * The octree is a cube of centre c and half size h (the `copc` info VLR, record 1, 160 bytes:
 * centre x y z, half size, spacing, the root hierarchy page's offset and size, GPS time min and
 * max, reserved). Node (d, x, y, z) is the cube of side \f$ s = 2h / 2^d \f$ whose least corner is
 * \f$ c - h + s\,(x, y, z) \f$, holding the points of that level (depth d holds points about
 * spacing / 2^d apart; every point lies in exactly one node). The hierarchy (an EVLR, `copc`
 * record 1000) is a tree of pages of 32-byte entries: key d x y z (4 x int32), offset (uint64),
 * byte size (int32), point count (int32); a count of -1 names another page (at offset, of byte
 * size bytes) instead of a node, 0 a node without points.
 *
 * Every offset, size and count is checked against the file before anything is read or
 * allocated; the pages may not form a cycle, the nodes' chunks may not overlap, and their counts
 * must add up to the header's (pcl_ddg::FileFormatException otherwise). A node's points are
 * decoded as any LAZ chunk.
 */
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "pcl_ddg/io/mesh_io.h"

namespace pcl_ddg {

/** A node of the octree: depth, then its cube's position along x, y, z at that depth. */
struct CopcKey {
  int depth = 0, x = 0, y = 0, z = 0;
  bool operator==(const CopcKey& other) const {
    return depth == other.depth && x == other.x && y == other.y && z == other.z;
  }
};

/** A node's entry in the hierarchy. */
struct CopcNode {
  CopcKey key;
  std::uint64_t offset = 0;  ///< of its chunk in the file
  std::uint32_t bytes = 0;   ///< its chunk's size
  std::uint32_t points = 0;  ///< 0: a node without points (no chunk)
};

/** A COPC file's octree, as its info VLR and hierarchy give it. */
struct CopcInfo {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double halfsize = 0.0;
  double spacing = 0.0;  ///< of the root level's points
  double gpstime_min = 0.0, gpstime_max = 0.0;
  std::uint64_t point_count = 0;  ///< the header's (the nodes' sum)
  /** The header's scale: a point's coordinates are rounded to it, so it may lie up to half a
   *  step outside its node's cube. */
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  std::uint64_t hierarchy_pages = 0;
  std::vector<CopcNode> nodes;  ///< every node, in the order the pages list them

  /** The cube of node key (closed). */
  Eigen::AlignedBox3d bounds(const CopcKey& key) const;
};

/** Whether the LAS or LAZ file at path is COPC (its header and VLRs are read, nothing else). */
bool isCopcFile(const std::string& path);

/** The octree of the COPC file at path: its header, VLRs and hierarchy pages are read, by byte
 *  ranges. @throws FileFormatException if it is not COPC or its hierarchy is inconsistent. */
CopcInfo readCopcInfo(const std::string& path);

/** What a partial read of a COPC file gives: the points, as readMeshFile gives a LAS file's
 *  (their layout's header and VLRs those of the file), and the bytes it read. */
struct CopcPoints {
  MeshFile file;
  std::uint64_t bytes_read = 0;  ///< header, VLRs, hierarchy and the nodes' chunks
};

/** The points of the chosen nodes (in that order), reading only their chunks.
 *  @throws pcl::BadArgumentException for a key the hierarchy does not hold. */
CopcPoints readCopcNodes(const std::string& path, const std::vector<CopcKey>& keys);

/** The points within box (closed, in the file's coordinates, X * scale + offset), from the nodes
 *  whose cubes, widened by a scale step, meet it, down to max_depth (-1: every level; a smaller
 *  depth gives a coarser sample). Only those nodes' chunks are read. */
CopcPoints readCopcBox(const std::string& path, const Eigen::AlignedBox3d& box, int max_depth = -1);

namespace detail {

/** Byte ranges of a file (or of bytes in memory, for the fuzzer): what the COPC reader reads. */
class ByteRanges {
 public:
  virtual ~ByteRanges() = default;
  virtual std::uint64_t size() const = 0;
  /** bytes [offset, offset + count), which the caller has checked lie within size(). */
  virtual std::string read(std::uint64_t offset, std::uint64_t count) = 0;
  std::uint64_t bytesRead() const { return bytes_read_; }

 protected:
  std::uint64_t bytes_read_ = 0;
};

/** readCopcInfo of any byte ranges. */
CopcInfo readCopcInfo(ByteRanges& file);
/** The LAS file (uncompressed, in memory) of the chosen nodes' points, in that order. */
std::string copcNodesAsLas(ByteRanges& file, const CopcInfo& info,
                           const std::vector<CopcKey>& keys);

}  // namespace detail

}  // namespace pcl_ddg
