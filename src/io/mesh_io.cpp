#include "pcl_ddg/io/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "byte_cursor.h"
#include "file_bytes.h"
#include "las_format.h"
#include "laz/laz_codec.h"
#include "loader_threads.h"
#include "mesh_formats.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/atomic_file.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace {

// The mesh with its colours in the layout a format's viewers read; a copy only when they differ.
const pcl::PolygonMesh& withColorLayout(const pcl::PolygonMesh& mesh, ColorLayout layout,
                                        pcl::PolygonMesh& converted) {
  const auto current = vertexColorLayout(mesh.cloud);
  if (!current || *current == layout) return mesh;
  converted = mesh;
  setVertexColors(converted.cloud, vertexColors(mesh.cloud), layout);
  return converted;
}

void savePCD(const std::string& path, const pcl::PolygonMesh& mesh, const SensorPose& pose) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw FileFormatException("cannot write '" + path + "': " + std::strerror(errno));
  pcl::PolygonMesh converted;
  detail::writePCD(out, withColorLayout(mesh, ColorLayout::PackedRGB, converted).cloud, pose);
  out.close();
  if (!out) throw FileFormatException(std::string("write failed: ") + std::strerror(errno));
}

void savePLY(const std::string& path, const pcl::PolygonMesh& mesh, PlyEncoding encoding,
             const FaceRows* rows) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  pcl::PolygonMesh converted;
  detail::writePLY(out, withColorLayout(mesh, ColorLayout::Channels, converted), encoding, rows);
  out.close();
  if (!out) throw FileFormatException(std::string("write failed: ") + std::strerror(errno));
}

void requireFloatRange(const Eigen::Matrix3Xd& positions) {
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    for (int d = 0; d < 3; ++d) {
      const double v = positions(d, i);
      if (std::isfinite(v) && std::abs(v) > std::numeric_limits<float>::max()) {
        std::ostringstream text;
        text << "vertex " << i << ": coordinate " << v
             << " is beyond float's range (PCL's point types are float)";
        throw FileFormatException(text.str());
      }
    }
  }
}

// The polygons as rows when they all have the same size; none otherwise.
FaceRows faceRowsOf(const std::vector<pcl::Vertices>& polygons) {
  FaceRows rows;
  const std::size_t corners = polygons.front().vertices.size();
  for (const pcl::Vertices& p : polygons)
    if (p.vertices.size() != corners || corners == 0) return rows;
  rows.corners = corners;
  rows.indices.reserve(polygons.size() * corners);
  for (const pcl::Vertices& p : polygons)
    rows.indices.insert(rows.indices.end(), p.vertices.begin(), p.vertices.end());
  return rows;
}

}  // namespace

namespace detail {

MeshFile lasMeshFile(std::string_view data, std::size_t spare_point_bytes) {
  LasCloud las = parseLAS(data, spare_point_bytes);
  MeshFile file;
  file.mesh = std::move(las.mesh);
  file.positions = std::move(las.positions);
  file.coordinate_precision = FieldPrecision::Double;  // X * scale + offset
  file.las = std::make_shared<const LasLayout>(std::move(las.layout));
  return file;
}

}  // namespace detail

std::string fileExtension(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

MeshFile readMeshFile(const std::string& path, EmptyFilePolicy empty, FaceStorage faces,
                      std::size_t spare_point_bytes) {
  const std::string ext = fileExtension(path);
  try {
    std::optional<detail::FileBytes> bytes;
    bytes.emplace(path);  // first: a missing file says so
    std::string_view data = bytes->view();
    std::string decompressed;
    if (ext == "las" || ext == "laz") {
      // LAZ (by its header's compression bits, whatever the name): its chunks decompressed on
      // every core into the LAS file it stands for, which is then read as any other.
      if (lasIsCompressed(data)) {
        decompressed = detail::lazToLas(data, detail::loaderThreads());
        data = decompressed;
        bytes.reset();
      }
      MeshFile file = detail::lasMeshFile(data, spare_point_bytes);
      if (file.positions.cols() == 0 && empty == EmptyFilePolicy::Refuse)
        throw FileFormatException("no points (the header counts none)");
      return file;
    }
    using Parser = pcl::PolygonMesh (*)(std::string_view);
    Parser parse = nullptr;
    if (ext == "ply") parse = detail::parsePLY;
    if (ext == "off") parse = [](std::string_view text) { return detail::parseOFF(text); };
    if (ext == "obj") parse = detail::parseOBJ;
    if (ext == "stl") parse = detail::parseSTL;
    if (ext == "vtk") parse = detail::parseVTK;
    if (parse == nullptr && ext != "pcd") {
      throw FileFormatException(
          (ext.empty() ? std::string("no file extension") : "unknown file type '." + ext + "'") +
          " (expected .ply, .obj, .off, .stl, .vtk, .pcd, .las or .laz)");
    }
    MeshFile file;
    auto rows = std::make_shared<FaceRows>();
    const bool as_rows = faces == FaceStorage::Rows;
    file.mesh = ext == "pcd" ? detail::parsePCD(data, &file.sensor_pose, spare_point_bytes)
                : ext == "off" && as_rows ? detail::parseOFF(data, rows.get())
                                          : parse(data);
    bytes.reset();  // parsed: its memory is free for the positions
    if (as_rows && !file.mesh.polygons.empty()) *rows = faceRowsOf(file.mesh.polygons);
    if (rows->rows() > 0) {
      std::vector<pcl::Vertices>().swap(file.mesh.polygons);
      file.faces = std::move(rows);
    }
    pcl::PCLPointCloud2& cloud = file.mesh.cloud;
    if (cloud.width * cloud.height == 0) throw FileFormatException("file has no vertices");
    file.positions = vertexPositions(cloud, NonFinitePolicy::Keep);
    requireFloatRange(file.positions);
    // Text OFF/OBJ/STL declare no type: their doubles are exact values of the text, not a choice.
    const bool typed = ext == "ply" || ext == "pcd" || ext == "vtk";
    const bool stored_double = std::any_of(cloud.fields.begin(), cloud.fields.end(), [](auto& f) {
      return (f.name == "x" || f.name == "y" || f.name == "z") &&
             f.datatype == pcl::PCLPointField::FLOAT64;
    });
    if (typed && stored_double) file.coordinate_precision = FieldPrecision::Double;
    // Float coordinates are PCL's already (and the positions their exact values).
    const bool all_float = std::all_of(cloud.fields.begin(), cloud.fields.end(), [](auto& f) {
      return !(f.name == "x" || f.name == "y" || f.name == "z") ||
             (f.datatype == pcl::PCLPointField::FLOAT32 && f.count == 1);
    });
    if (!all_float) setVertexCoordinates(cloud, file.positions, FieldPrecision::Float);
    return file;
  } catch (const pcl::PCLException& e) {
    throw FileFormatException(path + ": " + errorDescription(e));
  }
}

pcl::PolygonMesh loadMesh(const std::string& path, SensorPose* sensor_pose) {
  MeshFile file = readMeshFile(path);
  if (sensor_pose) *sensor_pose = file.sensor_pose;
  return std::move(file.mesh);
}

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh,
              const MeshWriteOptions& options) {
  const std::string ext = fileExtension(path);
  try {
    if (ext != "ply" && ext != "pcd" && ext != "las" && ext != "laz") {
      throw FileFormatException("cannot write '." + ext + "' files (use .ply, .pcd, .las or .laz)");
    }
    if (options.faces && !mesh.polygons.empty())
      throw pcl::BadArgumentException("faces given twice: as polygons and as rows");
    AtomicFile file(path);
    if (ext == "las") {
      detail::writeLAS(file.temporaryPath(), mesh.cloud, options.las.get());
    } else if (ext == "laz") {
      // The LAS file writeLAS would write, made in memory, then compressed (laz/laz_codec.h).
      const std::string las = detail::encodeLAS(
          mesh.cloud, vertexPositions(mesh.cloud, NonFinitePolicy::Keep), options.las.get());
      writeBytes(file.temporaryPath(), detail::lasToLaz(las));
    } else if (ext == "ply") {
      savePLY(file.temporaryPath(), mesh, options.ply_encoding, options.faces.get());
    } else {
      savePCD(file.temporaryPath(), mesh, options.sensor_pose);
    }
    file.commit();
  } catch (const pcl::PCLException& e) {
    throw FileFormatException(path + ": " + errorDescription(e));
  }
}

}  // namespace pcl_ddg
