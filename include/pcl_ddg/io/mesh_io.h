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

#include <string>

namespace pcl_ddg {

enum class PlyEncoding { Binary, Ascii };

struct MeshWriteOptions {
  PlyEncoding ply_encoding = PlyEncoding::Binary;
};

pcl::PolygonMesh loadMesh(const std::string& path);

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh,
              const MeshWriteOptions& options = {});

/** Lower-case extension without the dot ("ply"), empty if none. */
std::string fileExtension(const std::string& path);

}  // namespace pcl_ddg
