// Legacy VTK (".vtk") POLYDATA. Binary data is big-endian and starts after the keyword's line.
// Cells come either as "n i0 .. in-1" runs (classic) or as OFFSETS + CONNECTIVITY arrays (5.x).
#include <functional>
#include <vector>

#include "byte_cursor.h"
#include "mesh_formats.h"
#include "xyz_cloud.h"

namespace pcl_ddg {
namespace detail {
namespace {

enum class VtkEncoding { Ascii, Binary };

class VtkReader {
 public:
  VtkReader(ByteCursor& cursor, VtkEncoding encoding) : cursor_(cursor), encoding_(encoding) {}

  /** Reads n values of the named VTK type; binary data begins on the next line. Every value
   *  takes at least one byte, so a count beyond the remaining bytes is refused unallocated. */
  std::vector<double> values(std::int64_t n, std::string_view type, const char* what) {
    if (n < 0 || n > static_cast<std::int64_t>(cursor_.remaining())) {
      cursor_.fail(std::string("impossible value count for ") + what);
    }
    std::vector<double> out(static_cast<std::size_t>(n));
    if (encoding_ == VtkEncoding::Ascii) {
      for (double& v : out) v = cursor_.readDouble(what);
      return out;
    }
    cursor_.line();
    const std::function<double()> read = binaryReader(type, what);
    for (double& v : out) v = read();
    return out;
  }

 private:
  std::function<double()> binaryReader(std::string_view type, const char* what) {
    auto as = [this, what](auto zero) {
      return [this, what] {
        return static_cast<double>(cursor_.readBinary<decltype(zero)>(ByteOrder::Big, what));
      };
    };
    if (type == "float") return as(float{});
    if (type == "double") return as(double{});
    if (type == "int" || type == "vtktypeint32") return as(std::int32_t{});
    if (type == "unsigned_int" || type == "vtktypeuint32") return as(std::uint32_t{});
    if (type == "long" || type == "vtktypeint64") return as(std::int64_t{});
    if (type == "unsigned_long" || type == "vtktypeuint64") return as(std::uint64_t{});
    if (type == "short") return as(std::int16_t{});
    if (type == "unsigned_short") return as(std::uint16_t{});
    if (type == "char") return as(std::int8_t{});
    if (type == "unsigned_char") return as(std::uint8_t{});
    cursor_.fail("unknown VTK data type '" + std::string(type) + "'");
  }

  ByteCursor& cursor_;
  VtkEncoding encoding_;
};

// Cell data as integers; a value that is not one is refused.
std::vector<std::int64_t> integers(const std::vector<double>& values, const ByteCursor& cursor) {
  std::vector<std::int64_t> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    out[i] = cursor.convert<std::int64_t>(values[i], "a VTK cell index");
  }
  return out;
}

// Calls on_cell(indices, count) for every cell of a cell section.
void readCells(ByteCursor& cursor, VtkReader& reader,
               const std::function<void(const std::int64_t*, std::size_t)>& on_cell) {
  const std::int64_t first = cursor.readInt("cell count");
  const std::int64_t second = cursor.readInt("cell size");
  const std::size_t mark = cursor.position();
  std::vector<std::int64_t> indices;
  if (cursor.token() == "OFFSETS") {
    const std::vector<std::int64_t> offsets =
        integers(reader.values(first, cursor.requireToken("offset type"), "offsets"), cursor);
    if (cursor.token() != "CONNECTIVITY") cursor.fail("VTK OFFSETS without CONNECTIVITY");
    indices = integers(
        reader.values(second, cursor.requireToken("connectivity type"), "connectivity"), cursor);
    for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
      const std::int64_t begin = offsets[c];
      const std::int64_t end = offsets[c + 1];
      if (begin < 0 || end < begin || end > static_cast<std::int64_t>(indices.size())) {
        cursor.fail("VTK cell offsets out of range");
      }
      on_cell(indices.data() + begin, static_cast<std::size_t>(end - begin));
    }
    return;
  }
  // Classic layout: `second` integers as (n, i0 .. in-1) runs.
  cursor.seek(mark);
  indices = integers(reader.values(second, "int", "cells"), cursor);
  std::size_t at = 0;
  for (std::int64_t c = 0; c < first; ++c) {
    if (at >= indices.size()) cursor.fail("VTK cell list shorter than its cell count");
    const std::int64_t n = indices[at];
    if (n < 0 || n >= static_cast<std::int64_t>(indices.size() - at)) {
      cursor.fail("VTK cell runs past the end of its list");
    }
    on_cell(indices.data() + at + 1, static_cast<std::size_t>(n));
    at += 1 + static_cast<std::size_t>(n);
  }
}

}  // namespace

pcl::PolygonMesh parseVTK(std::string_view data) {
  ByteCursor cursor(data);
  if (cursor.line().rfind("# vtk DataFile", 0) != 0) cursor.fail("not a legacy VTK file");
  cursor.line();  // title
  const std::string_view encoding_name = cursor.requireToken("encoding");
  VtkEncoding encoding;
  if (encoding_name == "ASCII") {
    encoding = VtkEncoding::Ascii;
  } else if (encoding_name == "BINARY") {
    encoding = VtkEncoding::Binary;
  } else {
    cursor.fail("VTK encoding must be ASCII or BINARY");
  }
  if (cursor.requireToken("DATASET") != "DATASET" ||
      cursor.requireToken("dataset type") != "POLYDATA") {
    cursor.fail("only VTK POLYDATA is supported");
  }
  VtkReader reader(cursor, encoding);
  pcl::PolygonMesh mesh;
  bool has_points = false;
  for (std::string_view keyword = cursor.token(); !keyword.empty(); keyword = cursor.token()) {
    if (keyword == "POINTS") {
      const std::int64_t n = cursor.readInt("point count");
      const std::vector<double> xyz = reader.values(cursor.product(n, 3, "point count"),
                                                    cursor.requireToken("point type"), "points");
      mesh.cloud = makeXYZCloud(xyz);
      has_points = true;
    } else if (keyword == "POLYGONS" || keyword == "TRIANGLE_STRIPS" || keyword == "VERTICES" ||
               keyword == "LINES") {
      const bool polygons = keyword == "POLYGONS", strips = keyword == "TRIANGLE_STRIPS";
      readCells(cursor, reader, [&](const std::int64_t* cell, std::size_t n) {
        if (strips) {
          appendTriangleStrip(cell, n, mesh.polygons);
        } else if (polygons) {
          pcl::Vertices polygon;
          for (std::size_t k = 0; k < n; ++k) {
            polygon.vertices.push_back(cornerIndex(cell[k]));
          }
          mesh.polygons.push_back(std::move(polygon));
        }
      });
    } else if (keyword == "POINT_DATA" || keyword == "CELL_DATA" || keyword == "FIELD" ||
               keyword == "METADATA") {
      break;  // attributes are not geometry
    } else {
      cursor.fail("unexpected VTK keyword '" + std::string(keyword.substr(0, 40)) + "'");
    }
  }
  if (!has_points) cursor.fail("VTK file has no POINTS");
  return mesh;
}

}  // namespace detail
}  // namespace pcl_ddg
