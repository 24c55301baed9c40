// PLY reader and writer. Our own because PCL's reader (and VTK's) silently return zero faces for
// a `tristrips` face element; this one reads every element or fails with the reason.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>

#include <pcl/common/io.h>

#include "byte_cursor.h"
#include "loader_threads.h"
#include "mesh_formats.h"

namespace pcl_ddg {
namespace detail {
namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class PlyFormat { Ascii, BinaryLittleEndian, BinaryBigEndian };

bool isHostOrderBinary(PlyFormat format) {
  return format == (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__ ? PlyFormat::BinaryLittleEndian
                                                              : PlyFormat::BinaryBigEndian);
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::int64_t grid_columns = 0;
  std::int64_t grid_rows = 0;
};

PlyType parseType(std::string_view name, const ByteCursor& cursor) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const auto& [text, type] : kNames) {
    if (name == text) return type;
  }
  cursor.fail("unknown PLY property type '" + std::string(name) + "'");
}

std::uint32_t typeSize(PlyType type) {
  switch (type) {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
  }
  return 0;
}

std::uint8_t pclDatatype(PlyType type) {
  switch (type) {
    case PlyType::Int8:
      return pcl::PCLPointField::INT8;
    case PlyType::UInt8:
      return pcl::PCLPointField::UINT8;
    case PlyType::Int16:
      return pcl::PCLPointField::INT16;
    case PlyType::UInt16:
      return pcl::PCLPointField::UINT16;
    case PlyType::Int32:
      return pcl::PCLPointField::INT32;
    case PlyType::UInt32:
      return pcl::PCLPointField::UINT32;
    case PlyType::Float32:
      return pcl::PCLPointField::FLOAT32;
    case PlyType::Float64:
      return pcl::PCLPointField::FLOAT64;
  }
  return 0;
}

PlyHeader parseHeader(ByteCursor& cursor) {
  if (cursor.line() != "ply") cursor.fail("not a PLY file (first line is not 'ply')");
  PlyHeader header;
  bool has_format = false;
  for (;;) {
    if (cursor.atEnd()) cursor.fail("PLY header has no end_header");
    std::istringstream words{std::string(cursor.line())};
    std::string keyword;
    words >> keyword;
    if (keyword.empty() || keyword == "comment") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      std::string format;
      words >> format;
      if (format == "ascii") {
        header.format = PlyFormat::Ascii;
      } else if (format == "binary_little_endian") {
        header.format = PlyFormat::BinaryLittleEndian;
      } else if (format == "binary_big_endian") {
        header.format = PlyFormat::BinaryBigEndian;
      } else {
        cursor.fail("unknown PLY format '" + format + "'");
      }
      has_format = true;
    } else if (keyword == "obj_info") {
      std::string key;
      std::int64_t value = 0;
      words >> key >> value;
      if (key == "num_cols") header.grid_columns = value;
      if (key == "num_rows") header.grid_rows = value;
    } else if (keyword == "element") {
      PlyElement element;
      if (!(words >> element.name >> element.count) || element.count < 0) {
        cursor.fail("malformed PLY element line (a name and a count >= 0)");
      }
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) cursor.fail("PLY property before any element");
      PlyProperty property;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        property.is_list = true;
        property.count_type = parseType(count_type, cursor);
        property.type = parseType(item_type, cursor);
      } else {
        property.type = parseType(type, cursor);
      }
      if (!(words >> property.name)) cursor.fail("PLY property without a name");
      header.elements.back().properties.push_back(property);
    } else {
      cursor.fail("unknown PLY header keyword '" + keyword + "'");
    }
  }
  if (!has_format) cursor.fail("PLY header has no format line");
  for (const PlyElement& element : header.elements) {
    if (element.count > 0 && element.properties.empty()) {
      cursor.fail("PLY element '" + element.name + "' has rows but no properties");
    }
  }
  return header;
}

// The fewest bytes one row of the element can take: its binary sizes (lists empty), or in ascii
// a character and a separator per value.
std::int64_t minimumRowBytes(const PlyElement& element, PlyFormat format) {
  std::int64_t bytes = 0;
  for (const auto& p : element.properties) {
    bytes += format == PlyFormat::Ascii ? 2 : typeSize(p.is_list ? p.count_type : p.type);
  }
  return bytes;
}

/** Reads the values of a PLY body in either encoding. */
class PlyValueReader {
 public:
  PlyValueReader(ByteCursor& cursor, PlyFormat format)
      : cursor_(cursor),
        format_(format),
        order_(format == PlyFormat::BinaryBigEndian ? ByteOrder::Big : ByteOrder::Little) {}

  double number(PlyType type, const char* what) {
    if (format_ == PlyFormat::Ascii) return cursor_.readDouble(what);
    switch (type) {
      case PlyType::Int8:
        return cursor_.readBinary<std::int8_t>(order_, what);
      case PlyType::UInt8:
        return cursor_.readBinary<std::uint8_t>(order_, what);
      case PlyType::Int16:
        return cursor_.readBinary<std::int16_t>(order_, what);
      case PlyType::UInt16:
        return cursor_.readBinary<std::uint16_t>(order_, what);
      case PlyType::Int32:
        return cursor_.readBinary<std::int32_t>(order_, what);
      case PlyType::UInt32:
        return cursor_.readBinary<std::uint32_t>(order_, what);
      case PlyType::Float32:
        return cursor_.readBinary<float>(order_, what);
      case PlyType::Float64:
        return cursor_.readBinary<double>(order_, what);
    }
    return 0.0;
  }

  /** A list length: a non-negative integer whose items fit in the bytes that remain. */
  std::int64_t count(PlyType type, PlyType item_type, const char* what) {
    const double n = number(type, what);
    const std::uint32_t item_bytes = format_ == PlyFormat::Ascii ? 2 : typeSize(item_type);
    if (!(n >= 0.0) || n != std::floor(n) ||
        n > static_cast<double>(cursor_.remaining() / item_bytes + 1)) {
      cursor_.fail(std::string("invalid list length in ") + what +
                   " (more items than the file holds)");
    }
    return static_cast<std::int64_t>(n);
  }

  /** A vertex index: an integer value (of any stored type). */
  std::int64_t index(PlyType type, const char* what) {
    return cursor_.convert<std::int64_t>(number(type, what), "a vertex index");
  }

  /** Stores one scalar in its PLY type at dst (host byte order). */
  void scalarInto(PlyType type, std::uint8_t* dst, const char* what) {
    const std::uint32_t size = typeSize(type);
    if (format_ != PlyFormat::Ascii) {
      std::memcpy(dst, cursor_.take(size, what), size);
      if (order_ == ByteOrder::Big) std::reverse(dst, dst + size);
      return;
    }
    const double v = cursor_.readDouble(what);
    cursor_.storeAs(pclDatatype(type), v, dst, "the PLY property type");
  }

  void skip(const PlyProperty& property, const char* what) {
    const std::int64_t n = property.is_list ? count(property.count_type, property.type, what) : 1;
    for (std::int64_t i = 0; i < n; ++i) number(property.type, what);
  }

 private:
  ByteCursor& cursor_;
  PlyFormat format_;
  ByteOrder order_;
};

void readVertices(const PlyElement& element, PlyFormat format, PlyValueReader& reader,
                  ByteCursor& cursor, pcl::PCLPointCloud2& cloud) {
  std::uint32_t offset = 0;
  for (const auto& p : element.properties) {
    if (p.is_list) continue;  // per-vertex lists have no place in a point cloud
    pcl::PCLPointField field;
    field.name = p.name;
    field.offset = offset;
    field.datatype = pclDatatype(p.type);
    field.count = 1;
    cloud.fields.push_back(field);
    offset += typeSize(p.type);
  }
  // PCLPointCloud2 counts bytes in 32 bits (row_step).
  if (cursor.product(element.count, offset, "vertex count x vertex size") >
      std::numeric_limits<std::uint32_t>::max()) {
    cursor.fail("PLY vertex data too large for a pcl::PCLPointCloud2 (4 GiB)");
  }
  cloud.width = static_cast<std::uint32_t>(element.count);
  cloud.height = 1;
  cloud.point_step = offset;
  cloud.row_step = offset * cloud.width;
  cloud.data.resize(static_cast<std::size_t>(cloud.row_step));
  // Binary rows without lists, in this host's byte order, are the cloud's bytes already.
  const bool has_lists = std::any_of(element.properties.begin(), element.properties.end(),
                                     [](const PlyProperty& p) { return p.is_list; });
  cloud.is_dense = false;  // unknown until checked; consumers test finiteness themselves
  if (isHostOrderBinary(format) && !has_lists) {
    const char* rows = cursor.take(cloud.data.size(), "vertex");
    if (!cloud.data.empty()) std::memcpy(cloud.data.data(), rows, cloud.data.size());
    return;
  }
  for (std::int64_t i = 0; i < element.count; ++i) {
    std::uint8_t* point = cloud.data.data() + i * offset;
    std::size_t field = 0;
    for (const auto& p : element.properties) {
      if (p.is_list) {
        reader.skip(p, "vertex list property");
      } else {
        reader.scalarInto(p.type, point + cloud.fields[field++].offset, "vertex");
      }
    }
  }
}

const PlyProperty* indexList(const PlyElement& element) {
  for (const auto& p : element.properties) {
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) return &p;
  }
  return nullptr;
}

// Calls on_list(indices) for each row's index list; other properties are skipped.
template <typename OnList>
void readIndexLists(const PlyElement& element, PlyValueReader& reader, ByteCursor& cursor,
                    OnList on_list) {
  const PlyProperty* list = indexList(element);
  if (list == nullptr) cursor.fail("PLY element '" + element.name + "' has no vertex_indices list");
  std::vector<std::int64_t> indices;
  for (std::int64_t row = 0; row < element.count; ++row) {
    for (const auto& p : element.properties) {
      if (&p != list) {
        reader.skip(p, element.name.c_str());
        continue;
      }
      const std::int64_t n = reader.count(p.count_type, p.type, element.name.c_str());
      indices.resize(static_cast<std::size_t>(n));
      for (auto& index : indices) index = reader.index(p.type, element.name.c_str());
      on_list(indices);
    }
  }
}

// The face layout nearly every binary writer uses: rows of only `list uchar int|uint
// vertex_indices`, in this host's byte order. Read directly rather than value by value; false for
// any other layout (the general reader takes it).
bool readPlainBinaryFaces(const PlyElement& element, PlyFormat format, ByteCursor& cursor,
                          std::vector<pcl::Vertices>& polygons) {
  if (!isHostOrderBinary(format) || element.properties.size() != 1 ||
      indexList(element) != &element.properties.front()) {
    return false;
  }
  const PlyProperty& list = element.properties.front();
  if (list.count_type != PlyType::UInt8 ||
      (list.type != PlyType::Int32 && list.type != PlyType::UInt32)) {
    return false;
  }
  // One bounds-checked pass over the row sizes marks where each block of rows starts; the blocks
  // are then read in parallel, so that the one allocation every pcl::Vertices needs (a third of
  // the load) is spread over the threads' own heaps.
  constexpr std::size_t kBlockRows = 4096;
  const auto rows = static_cast<std::size_t>(element.count);
  std::vector<const char*> block_starts;
  block_starts.reserve(rows / kBlockRows + 1);
  for (std::size_t row = 0; row < rows; ++row) {
    const char* start = cursor.take(1, "face");
    if (row % kBlockRows == 0) block_starts.push_back(start);
    cursor.skip(4 * std::size_t{static_cast<std::uint8_t>(*start)}, "face");
  }
  const std::size_t first = polygons.size();
  polygons.resize(first + rows);
  const bool is_unsigned = list.type == PlyType::UInt32;
  const auto blocks = static_cast<std::int64_t>(block_starts.size());
  parallelForInLoader(blocks, 1, [&](std::int64_t block) {
    const char* bytes = block_starts[static_cast<std::size_t>(block)];
    const std::size_t end = std::min(rows, static_cast<std::size_t>(block + 1) * kBlockRows);
    for (std::size_t row = static_cast<std::size_t>(block) * kBlockRows; row < end; ++row) {
      const std::size_t n = static_cast<std::uint8_t>(*bytes++);
      std::vector<pcl::index_t>& corners = polygons[first + row].vertices;
      corners.resize(n);
      for (std::size_t k = 0; k < n; ++k, bytes += 4) {
        std::uint32_t bits;
        std::memcpy(&bits, bytes, 4);
        corners[k] = cornerIndex(is_unsigned ? std::int64_t{bits}
                                             : std::int64_t{static_cast<std::int32_t>(bits)});
      }
    }
  });
  return true;
}

// Lays the scan out on its range grid: row-major cells, a point where the grid names one, NaN
// (non-float fields zero) where it is empty.
pcl::PCLPointCloud2 organizeOnGrid(const pcl::PCLPointCloud2& points,
                                   const std::vector<std::int64_t>& cell_point,
                                   const PlyHeader& header, const ByteCursor& cursor) {
  pcl::PCLPointCloud2 grid = points;
  grid.width = static_cast<std::uint32_t>(header.grid_columns);
  grid.height = static_cast<std::uint32_t>(header.grid_rows);
  grid.row_step = grid.point_step * grid.width;
  grid.data.assign(static_cast<std::size_t>(grid.row_step) * grid.height, 0);
  grid.is_dense = false;
  const float nan_f = std::numeric_limits<float>::quiet_NaN();
  const double nan_d = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t cell = 0; cell < cell_point.size(); ++cell) {
    std::uint8_t* dst = grid.data.data() + cell * grid.point_step;
    const std::int64_t i = cell_point[cell];
    if (i >= static_cast<std::int64_t>(points.width)) {
      cursor.fail("range_grid names vertex " + std::to_string(i) + " of " +
                  std::to_string(points.width));
    }
    if (i >= 0) {
      std::memcpy(dst, points.data.data() + i * points.point_step, points.point_step);
      continue;
    }
    for (const auto& f : grid.fields) {
      if (f.datatype == pcl::PCLPointField::FLOAT32) std::memcpy(dst + f.offset, &nan_f, 4);
      if (f.datatype == pcl::PCLPointField::FLOAT64) std::memcpy(dst + f.offset, &nan_d, 8);
    }
  }
  return grid;
}

}  // namespace

std::string editLines(const std::string& text, void (*edit)(std::string& line, std::int64_t count),
                      std::int64_t count) {
  std::istringstream lines(text);
  std::string out;
  for (std::string line; std::getline(lines, line);) {
    edit(line, count);
    out += line + "\n";
  }
  return out;
}

std::string plyHeaderWithVertices(const std::string& header, std::int64_t count) {
  return editLines(
      header,
      [](std::string& line, std::int64_t n) {
        if (line.rfind("element vertex ", 0) == 0) line = "element vertex " + std::to_string(n);
      },
      count);
}

BinaryCloudLayout plyBinaryLayout(std::string_view head) {
  ByteCursor cursor(head);
  const PlyHeader header = parseHeader(cursor);
  if (header.format == PlyFormat::Ascii) cursor.fail("only a binary PLY is read a piece at a time");
  BinaryCloudLayout layout;
  bool has_vertices = false;
  for (const PlyElement& element : header.elements) {
    if (element.name != "vertex") {
      if (element.count > 0) {
        cursor.fail("PLY element '" + element.name +
                    "' has rows: only a cloud (vertices alone) "
                    "is read a piece at a time");
      }
      continue;
    }
    if (has_vertices) cursor.fail("PLY file has a second vertex element");
    has_vertices = true;
    layout.points = element.count;
    for (const auto& p : element.properties) {
      if (p.is_list) cursor.fail("PLY vertex property '" + p.name + "' is a list");
      layout.point_bytes += typeSize(p.type);
    }
  }
  if (!has_vertices || layout.points == 0) cursor.fail("PLY file has no vertices");
  layout.header_bytes = static_cast<std::int64_t>(cursor.position());
  layout.width = static_cast<std::uint32_t>(
      std::min<std::int64_t>(layout.points, std::numeric_limits<std::uint32_t>::max()));
  layout.height = 1;
  layout.header = std::string(head.substr(0, cursor.position()));
  layout.header_for = plyHeaderWithVertices;
  return layout;
}

pcl::PolygonMesh parsePLY(std::string_view data) {
  ByteCursor cursor(data);
  const PlyHeader header = parseHeader(cursor);
  PlyValueReader reader(cursor, header.format);
  pcl::PolygonMesh mesh;
  bool has_vertices = false;
  std::vector<std::int64_t> grid_cells;
  bool has_grid = false;
  for (const PlyElement& element : header.elements) {
    // A count the remaining bytes cannot hold is a lie: refused before anything is reserved.
    if (cursor.product(element.count, minimumRowBytes(element, header.format), "element size") >
        static_cast<std::int64_t>(cursor.remaining())) {
      cursor.fail("PLY element '" + element.name + "' claims " + std::to_string(element.count) +
                  " rows, more than the file holds (truncated?)");
    }
    if (element.name == "vertex") {
      if (has_vertices) cursor.fail("PLY file has a second vertex element");
      readVertices(element, header.format, reader, cursor, mesh.cloud);
      has_vertices = true;
    } else if (element.name == "face") {
      mesh.polygons.reserve(mesh.polygons.size() + static_cast<std::size_t>(element.count));
      if (readPlainBinaryFaces(element, header.format, cursor, mesh.polygons)) continue;
      readIndexLists(element, reader, cursor, [&](const std::vector<std::int64_t>& indices) {
        pcl::Vertices polygon;
        polygon.vertices.reserve(indices.size());
        for (std::int64_t i : indices) polygon.vertices.push_back(cornerIndex(i));
        mesh.polygons.push_back(std::move(polygon));
      });
    } else if (element.name == "tristrips") {
      readIndexLists(element, reader, cursor, [&](const std::vector<std::int64_t>& strip) {
        appendTriangleStrip(strip.data(), strip.size(), mesh.polygons);
      });
    } else if (element.name == "range_grid") {
      has_grid = true;
      grid_cells.reserve(static_cast<std::size_t>(element.count));
      readIndexLists(element, reader, cursor, [&](const std::vector<std::int64_t>& cell) {
        grid_cells.push_back(cell.empty() ? -1 : cell.front());
      });
    } else {
      for (std::int64_t row = 0; row < element.count; ++row) {
        for (const auto& p : element.properties) reader.skip(p, element.name.c_str());
      }
    }
  }
  if (!has_vertices) cursor.fail("PLY file has no vertex element");
  if (has_grid && mesh.polygons.empty()) {
    const auto cells = static_cast<std::int64_t>(grid_cells.size());
    if (header.grid_columns <= 0 || header.grid_rows <= 0 || header.grid_columns > cells ||
        header.grid_rows > cells / header.grid_columns ||
        header.grid_columns * header.grid_rows != cells) {
      cursor.fail("range_grid size does not match obj_info num_cols x num_rows");
    }
    mesh.cloud = organizeOnGrid(mesh.cloud, grid_cells, header, cursor);
  }
  return mesh;
}

namespace {

const char* plyTypeName(std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return "char";
    case pcl::PCLPointField::UINT8:
      return "uchar";
    case pcl::PCLPointField::INT16:
      return "short";
    case pcl::PCLPointField::UINT16:
      return "ushort";
    case pcl::PCLPointField::INT32:
      return "int";
    case pcl::PCLPointField::UINT32:
      return "uint";
    case pcl::PCLPointField::FLOAT64:
      return "double";
    default:
      return "float";
  }
}

// One PLY scalar property to write: a cloud field, or one channel of a packed rgb(a) field.
struct OutputProperty {
  std::string name;
  std::uint8_t datatype;
  std::uint32_t offset;
};

std::vector<OutputProperty> outputProperties(const pcl::PCLPointCloud2& cloud) {
  std::vector<OutputProperty> properties;
  for (const auto& f : cloud.fields) {
    if (f.name == "rgb" || f.name == "rgba") {
      // PCL packs colour as BGRA bytes in a 4-byte field; PLY viewers expect uchar channels.
      properties.push_back({"red", pcl::PCLPointField::UINT8, f.offset + 2});
      properties.push_back({"green", pcl::PCLPointField::UINT8, f.offset + 1});
      properties.push_back({"blue", pcl::PCLPointField::UINT8, f.offset + 0});
      if (f.name == "rgba")
        properties.push_back({"alpha", pcl::PCLPointField::UINT8, f.offset + 3});
    } else if (f.count == 1 && !f.name.empty() && f.name != "_" &&
               f.datatype != pcl::PCLPointField::INT64 &&
               f.datatype != pcl::PCLPointField::UINT64) {
      // PLY has no 64-bit integers (a LAS extra-bytes or waveform offset field): left out, as
      // fields of several values are, rather than written as 8 bytes under a 4-byte type.
      properties.push_back({f.name, f.datatype, f.offset});
    }
  }
  return properties;
}

template <typename T>
void printValue(std::ostream& out, const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if constexpr (sizeof(T) == 1) {
    out << static_cast<int>(v);
  } else {
    out << v;
  }
}

void printScalar(std::ostream& out, const std::uint8_t* p, std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      printValue<std::int8_t>(out, p);
      break;
    case pcl::PCLPointField::UINT8:
      printValue<std::uint8_t>(out, p);
      break;
    case pcl::PCLPointField::INT16:
      printValue<std::int16_t>(out, p);
      break;
    case pcl::PCLPointField::UINT16:
      printValue<std::uint16_t>(out, p);
      break;
    case pcl::PCLPointField::INT32:
      printValue<std::int32_t>(out, p);
      break;
    case pcl::PCLPointField::UINT32:
      printValue<std::uint32_t>(out, p);
      break;
    case pcl::PCLPointField::FLOAT64:
      out << std::setprecision(std::numeric_limits<double>::max_digits10);
      printValue<double>(out, p);
      break;
    default:
      out << std::setprecision(std::numeric_limits<float>::max_digits10);
      printValue<float>(out, p);
  }
}

// Bytes gathered in a reused buffer and written in large blocks: a stream write per value costs
// more than the data, and one buffer of the whole body costs its page faults.
class BlockWriter {
 public:
  explicit BlockWriter(std::ostream& out) : out_(out) { buffer_.reserve(kBlock); }
  ~BlockWriter() { flush(); }
  void append(const void* data, std::size_t size) {
    if (buffer_.size() + size > kBlock) flush();
    buffer_.append(static_cast<const char*>(data), size);
  }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

 private:
  static constexpr std::size_t kBlock = 1 << 20;
  std::ostream& out_;
  std::string buffer_;
};

// Little-endian: the byte order of every platform PCL supports.
void writeBinaryBody(std::ostream& out, const pcl::PolygonMesh& mesh,
                     const std::vector<OutputProperty>& properties, bool wide_counts,
                     const FaceRows* rows) {
  const pcl::PCLPointCloud2& cloud = mesh.cloud;
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  BlockWriter writer(out);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* point = cloud.data.data() + i * cloud.point_step;
    for (const auto& p : properties) writer.append(point + p.offset, pcl::getFieldSize(p.datatype));
  }
  const auto writeCount = [&](std::size_t count) {
    const auto corners = static_cast<std::int32_t>(count);
    if (wide_counts) {
      writer.append(&corners, 4);
    } else {
      const auto narrow = static_cast<std::uint8_t>(corners);
      writer.append(&narrow, 1);
    }
  };
  if (rows != nullptr) {
    for (std::size_t r = 0; r < rows->rows(); ++r) {
      writeCount(rows->corners);
      writer.append(rows->indices.data() + r * rows->corners, 4 * rows->corners);
    }
    return;
  }
  for (const auto& polygon : mesh.polygons) {
    writeCount(polygon.vertices.size());
    static_assert(sizeof(pcl::index_t) == 4, "PLY indices are written as int32");
    writer.append(polygon.vertices.data(), 4 * polygon.vertices.size());
  }
}

}  // namespace

void writePLY(std::ostream& out, const pcl::PolygonMesh& mesh, PlyEncoding encoding,
              const FaceRows* rows) {
  const pcl::PCLPointCloud2& cloud = mesh.cloud;
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  const std::vector<OutputProperty> properties = outputProperties(cloud);
  const bool binary = encoding == PlyEncoding::Binary;
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
      << "comment written by pcl_ddg\n"
      << "element vertex " << n << "\n";
  for (const auto& p : properties)
    out << "property " << plyTypeName(p.datatype) << " " << p.name << "\n";
  // The usual uchar corner count, or int when a face has more than 255 corners.
  std::size_t most_corners = rows != nullptr ? rows->corners : 0;
  for (const auto& polygon : mesh.polygons)
    most_corners = std::max(most_corners, polygon.vertices.size());
  if (most_corners > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    throw FileFormatException("a face has too many corners for PLY");
  }
  const bool wide_counts = most_corners > 255;
  out << "element face " << (rows != nullptr ? rows->rows() : mesh.polygons.size()) << "\n"
      << "property list " << (wide_counts ? "int" : "uchar") << " int vertex_indices\nend_header\n";
  if (binary) {
    writeBinaryBody(out, mesh, properties, wide_counts, rows);
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* point = cloud.data.data() + i * cloud.point_step;
    for (std::size_t k = 0; k < properties.size(); ++k) {
      if (k) out << ' ';
      printScalar(out, point + properties[k].offset, properties[k].datatype);
    }
    out << '\n';
  }
  if (rows != nullptr) {
    for (std::size_t r = 0; r < rows->rows(); ++r) {
      out << rows->corners;
      for (std::size_t c = 0; c < rows->corners; ++c)
        out << ' ' << rows->indices[r * rows->corners + c];
      out << '\n';
    }
    return;
  }
  for (const auto& polygon : mesh.polygons) {
    out << polygon.vertices.size();
    for (const pcl::index_t v : polygon.vertices) out << ' ' << v;
    out << '\n';
  }
}

}  // namespace detail
}  // namespace pcl_ddg
