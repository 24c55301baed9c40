#include "pcl_ddg/io/mesh_io.h"

#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cctype>
#include <fstream>

#include "byte_cursor.h"
#include "formats.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/atomic_file.h"

namespace pcl_ddg {
namespace {

// PCL's PCD reader crashes on empty, garbage or truncated files, so the header and the data size
// are checked here first.
void checkPCD(const std::string& data) {
  detail::ByteCursor cursor(data);
  std::int64_t points = -1, point_size = 0;
  for (;;) {
    if (cursor.atEnd()) cursor.fail("not a PCD file (no DATA line)");
    detail::ByteCursor line = cursor.within(cursor.line());
    const std::string_view key = line.token();
    if (key.empty() || key.front() == '#' || key == "VERSION" || key == "FIELDS" || key == "TYPE" ||
        key == "WIDTH" || key == "HEIGHT" || key == "VIEWPOINT") {
      continue;
    }
    if (key == "SIZE" || key == "COUNT") {
      std::vector<std::int64_t> values;
      for (std::string_view t = line.token(); !t.empty(); t = line.token()) {
        values.push_back(line.parseInt(t, "SIZE/COUNT"));
      }
      if (key == "SIZE") {
        point_size = 0;
        for (std::int64_t v : values) point_size += v;
      }
    } else if (key == "POINTS") {
      points = line.readInt("POINTS");
    } else if (key == "DATA") {
      const std::string_view kind = line.requireToken("DATA kind");
      if (points <= 0) cursor.fail("PCD file has no points");
      if (kind == "binary" && cursor.remaining() < static_cast<std::size_t>(points * point_size)) {
        cursor.fail("PCD data shorter than POINTS x point size (truncated?)");
      }
      if (kind == "ascii") {
        std::int64_t rows = 0;
        while (!cursor.atEnd()) rows += !cursor.line().empty();
        if (rows < points) cursor.fail("PCD data has fewer rows than POINTS (truncated?)");
      }
      return;
    } else {
      cursor.fail("not a PCD file (unknown header line '" + std::string(key.substr(0, 20)) + "')");
    }
  }
}

pcl::PolygonMesh loadPCD(const std::string& path) {
  checkPCD(detail::readWholeFile(path));
  pcl::PolygonMesh mesh;
  pcl::PCDReader reader;
  if (reader.read(path, mesh.cloud) < 0) throw FileFormatException("not a readable PCD file");
  return mesh;
}

void savePCD(const std::string& path, const pcl::PolygonMesh& mesh) {
  pcl::PCDWriter writer;
  if (writer.writeBinary(path, mesh.cloud) < 0) throw FileFormatException("PCD writer failed");
}

void savePLY(const std::string& path, const pcl::PolygonMesh& mesh, PlyEncoding encoding) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  detail::writePLY(out, mesh, encoding);
  out.flush();
  if (!out) throw FileFormatException("write failed (disk full?)");
}

}  // namespace

std::string fileExtension(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

pcl::PolygonMesh loadMesh(const std::string& path) {
  const std::string ext = fileExtension(path);
  try {
    if (ext == "pcd") {
      return loadPCD(path);
    }
    using Parser = pcl::PolygonMesh (*)(std::string_view);
    Parser parse = nullptr;
    if (ext == "ply") parse = detail::parsePLY;
    if (ext == "off") parse = detail::parseOFF;
    if (ext == "obj") parse = detail::parseOBJ;
    if (ext == "stl") parse = detail::parseSTL;
    if (ext == "vtk") parse = detail::parseVTK;
    if (parse == nullptr) {
      throw FileFormatException("unknown file type '." + ext +
                                "' (expected ply, obj, off, stl, vtk or pcd)");
    }
    const std::string data = detail::readWholeFile(path);
    pcl::PolygonMesh mesh = parse(data);
    if (mesh.cloud.width * mesh.cloud.height == 0)
      throw FileFormatException("file has no vertices");
    return mesh;
  } catch (const FileFormatException& e) {
    throw FileFormatException(path + ": " + e.what());
  } catch (const pcl::PCLException& e) {
    throw FileFormatException(path + ": " + e.what());
  }
}

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh,
              const MeshWriteOptions& options) {
  const std::string ext = fileExtension(path);
  try {
    if (ext != "ply" && ext != "pcd") {
      throw FileFormatException("cannot write '." + ext + "' files (use .ply or .pcd)");
    }
    AtomicFile file(path);
    if (ext == "ply") {
      savePLY(file.temporaryPath(), mesh, options.ply_encoding);
    } else {
      savePCD(file.temporaryPath(), mesh);
    }
    file.commit();
  } catch (const pcl::PCLException& e) {
    throw FileFormatException(path + ": " + e.what());
  }
}

}  // namespace pcl_ddg
