#pragma once
/** \file
 * Loading and saving meshes and clouds, the format chosen by the file extension (case-insensitive).
 *
 * Read: .ply (ascii/binary; face, tristrips or range_grid elements), .obj, .off (also binary OFF),
 * .stl (ascii/binary), .vtk (legacy POLYDATA), .pcd (organized or not; no faces), .las (LAS
 * 1.0-1.4, point formats 0-10) and .laz (LASzip-compressed LAS: formats 0-3 and 6-8, COPC
 * included; told by the header, whatever the name). Written: .ply (binary by default), .pcd
 * (binary_compressed, as PCL's tools write it; faces are not stored), .las (the input's LAS
 * layout when given, else LAS 1.4 format 6/7) and .laz (the .las compressed). Colours
 * are written as each format's viewers read them (ColorLayout): PLY red green blue, PCD a packed
 * rgb. A cloud is a mesh without polygons. The mesh hands PCL what its point types read: x, y, z as
 * FLOAT32 (pcl::fromPCLPointCloud2 into pcl::PointXYZ works after any load); the coordinates as
 * the file holds them (double text, binary doubles) are kept exactly beside it (MeshFile).
 * Every other vertex field is kept as stored. Malformed, truncated or unknown files raise
 * FileFormatException with the path and the reason; output goes through a temporary file renamed on
 * success, so a failed save leaves no file behind.
 */
#include <pcl/PolygonMesh.h>

#include <Eigen/Geometry>
#include <memory>
#include <string>

#include "pcl_ddg/io/las_layout.h"
#include "pcl_ddg/io/vertex_fields.h"

namespace pcl_ddg {

enum class PlyEncoding { Binary, Ascii };

/** Where the sensor was: a PCD file's VIEWPOINT (translation, then orientation as w x y z). The
 *  origin and no rotation when a file has none. PCL's tools orient normals towards it. */
struct SensorPose {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/** A mesh's faces as one block, row after row, each of `corners` corners (NumPy's (m, k) layout):
 *  a .ply output writes them as they are, without a pcl::Vertices per face. */
struct FaceRows {
  std::vector<std::int32_t> indices;  ///< rows() * corners vertex indices
  std::size_t corners = 3;
  std::size_t rows() const { return corners > 0 ? indices.size() / corners : 0; }
};

struct MeshWriteOptions {
  PlyEncoding ply_encoding = PlyEncoding::Binary;
  /** The faces, when the mesh's polygons are empty and its faces are one block (a .pcd or .las
   *  output stores no faces, as with polygons). */
  std::shared_ptr<const FaceRows> faces;
  SensorPose sensor_pose;  ///< written as a PCD's VIEWPOINT
  /** A .las output keeps this layout (a LAS input's MeshFile::las): version, point format, scale,
   *  offset and every VLR. Null: LAS 1.4 format 6 (7 with colours), scale and offset chosen. */
  std::shared_ptr<const LasLayout> las;
};

/** A loaded file: the mesh as PCL code reads it, and what float fields cannot hold. */
struct MeshFile {
  pcl::PolygonMesh mesh;       ///< x, y, z as FLOAT32; every other field as stored
  Eigen::Matrix3Xd positions;  ///< the file's coordinates in double, exact (NaN kept)
  /** Double when the file declares double coordinates (PLY `double x`, PCD `F 8`, VTK
   *  `double`), so that a tool writes them back as such; Float for float and untyped text. */
  FieldPrecision coordinate_precision = FieldPrecision::Float;
  SensorPose sensor_pose;  ///< a PCD file's VIEWPOINT
  /** A LAS file's header, VLRs and Extra Bytes layout (null for other formats). Its coordinates
   *  are X * scale + offset in double (positions; coordinate_precision Double). */
  std::shared_ptr<const LasLayout> las;
  /** FaceStorage::Rows and every face of the same size: the faces, mesh.polygons left empty. */
  std::shared_ptr<const FaceRows> faces;
};

/** How readMeshFile returns a mesh's faces. */
enum class FaceStorage {
  Polygons,  ///< in mesh.polygons, as PCL code reads them
  /** In MeshFile::faces when they all have the same size (else as polygons): no heap vector per
   *  face, a quarter of the memory (what the tools read; MeshTopology and the .ply writer take
   *  them as they are). An ascii OFF of triangles is read straight into them. */
  Rows
};

/** What readMeshFile does with a valid LAS file whose header counts no point. (A file of another
 *  format without vertices is refused either way: there is nothing in it to report.) */
enum class EmptyFilePolicy {
  Refuse,  ///< FileFormatException naming the file, "no points": nothing to compute on
  Accept   ///< returned with no points and its header in MeshFile::las: to report on it
};

/** Loads any supported file. Throws FileFormatException when a finite coordinate lies beyond
 *  float's range (PCL's point types could not hold it), and for a file of no points unless
 *  empty is Accept and the file is LAS.
 *
 *  spare_point_bytes: room reserved in a LAS or PCD cloud's mesh.cloud.data for that many more
 *  bytes per point, untouched (no memory is used until written), so that the fields a caller adds
 *  (setVertexFields: normals, curvature, double coordinates) widen the rows in place instead of
 *  holding the cloud twice. */
MeshFile readMeshFile(const std::string& path, EmptyFilePolicy empty = EmptyFilePolicy::Refuse,
                      FaceStorage faces = FaceStorage::Polygons, std::size_t spare_point_bytes = 0);

/** readMeshFile's mesh; `sensor_pose`, if given, receives the file's VIEWPOINT (PCD). */
pcl::PolygonMesh loadMesh(const std::string& path, SensorPose* sensor_pose = nullptr);

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh,
              const MeshWriteOptions& options = {});

/** Lower-case extension without the dot ("ply"), empty if none. */
std::string fileExtension(const std::string& path);

}  // namespace pcl_ddg
