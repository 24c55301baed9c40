#pragma once
// Loading and saving meshes and clouds, the format chosen by the file extension (case-insensitive).
//
// Read: .ply (ascii/binary; face, tristrips or range_grid elements), .obj, .off (also binary OFF),
// .stl (ascii/binary), .vtk (legacy POLYDATA), .pcd (organized or not; no faces).
// Written: .ply (binary by default) and .pcd (binary_compressed, as PCL's tools write it; faces
// are not stored).
// A cloud is a mesh without polygons. All vertex fields are kept as they are stored (a double
// coordinate stays double). Malformed, truncated or unknown files raise FileFormatException with
// the path and the reason; output goes through a temporary file renamed on success, so a failed
// save leaves no file behind.
#include <pcl/PolygonMesh.h>

#include <Eigen/Geometry>
#include <string>

namespace pcl_ddg {

enum class PlyEncoding { Binary, Ascii };

/** Where the sensor was: a PCD file's VIEWPOINT (translation, then orientation as w x y z). The
 *  origin and no rotation when a file has none. PCL's tools orient normals towards it. */
struct SensorPose {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

struct MeshWriteOptions {
  PlyEncoding ply_encoding = PlyEncoding::Binary;
  SensorPose sensor_pose;  ///< written as a PCD's VIEWPOINT
};

/** Loads any supported file; `sensor_pose`, if given, receives the file's VIEWPOINT (PCD). */
pcl::PolygonMesh loadMesh(const std::string& path, SensorPose* sensor_pose = nullptr);

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh,
              const MeshWriteOptions& options = {});

/** Lower-case extension without the dot ("ply"), empty if none. */
std::string fileExtension(const std::string& path);

}  // namespace pcl_ddg
