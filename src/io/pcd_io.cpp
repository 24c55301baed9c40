// PCD (PCL's own format), read here rather than by pcl::PCDReader: PCL's reader trusts the header
// (negative or huge COUNT, WIDTH x HEIGHT != POINTS, lying compressed sizes) and crashes on it.
// Every size is checked against the bytes the file really holds before anything is allocated.
#include <lzf.h>

#include <pcl/common/io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <locale>
#include <sstream>
#include <vector>

#include "byte_cursor.h"
#include "mesh_formats.h"

namespace pcl_ddg {
namespace detail {
namespace {

enum class PcdData { Ascii, Binary, BinaryCompressed };

struct PcdHeader {
  std::vector<pcl::PCLPointField> fields;
  std::vector<std::int64_t> sizes;
  std::vector<char> types;
  std::vector<std::int64_t> counts;
  std::int64_t width = -1;
  std::int64_t height = 1;
  std::int64_t points = -1;
  std::int64_t point_size = 0;  ///< bytes of one point, all fields (padding "_" included)
  SensorPose sensor_pose;
  PcdData data = PcdData::Ascii;
};

std::uint8_t pcdDatatype(char type, std::int64_t size, const ByteCursor& cursor) {
  if (type == 'F' && size == 4) return pcl::PCLPointField::FLOAT32;
  if (type == 'F' && size == 8) return pcl::PCLPointField::FLOAT64;
  if (type == 'I' && size == 1) return pcl::PCLPointField::INT8;
  if (type == 'I' && size == 2) return pcl::PCLPointField::INT16;
  if (type == 'I' && size == 4) return pcl::PCLPointField::INT32;
  if (type == 'I' && size == 8) return pcl::PCLPointField::INT64;
  if (type == 'U' && size == 1) return pcl::PCLPointField::UINT8;
  if (type == 'U' && size == 2) return pcl::PCLPointField::UINT16;
  if (type == 'U' && size == 4) return pcl::PCLPointField::UINT32;
  if (type == 'U' && size == 8) return pcl::PCLPointField::UINT64;
  cursor.fail("unsupported PCD field type " + std::string(1, type) + " of size " +
              std::to_string(size));
}

// The values after a header keyword, as integers in [low, high].
std::vector<std::int64_t> integers(ByteCursor& line, const char* what, std::int64_t low,
                                   std::int64_t high) {
  std::vector<std::int64_t> values;
  for (std::string_view t = line.token(); !t.empty(); t = line.token()) {
    const std::int64_t v = line.parseInt(t, what);
    if (v < low || v > high) {
      line.fail(std::string(what) + " " + std::to_string(v) + " is out of range " +
                std::to_string(low) + ".." + std::to_string(high));
    }
    values.push_back(v);
  }
  return values;
}

PcdHeader parseHeader(ByteCursor& cursor) {
  PcdHeader header;
  std::vector<std::string> names;
  for (;;) {
    if (cursor.atEnd()) cursor.fail("not a PCD file (no DATA line)");
    ByteCursor line = cursor.within(cursor.line());
    const std::string_view key = line.token();
    if (key.empty() || key.front() == '#' || key == "VERSION") continue;
    if (key == "VIEWPOINT") {
      double v[7];
      for (double& value : v) value = line.readDouble("VIEWPOINT");
      const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
      if (!Eigen::Vector3d(v[0], v[1], v[2]).allFinite() || !(q.norm() > 0.0) ||
          !std::isfinite(q.norm())) {
        line.fail("PCD VIEWPOINT needs a finite position and a non-zero quaternion");
      }
      header.sensor_pose = {Eigen::Vector3d(v[0], v[1], v[2]), q.normalized()};
      continue;
    }
    if (key == "FIELDS" || key == "COLUMNS") {
      for (std::string_view t = line.token(); !t.empty(); t = line.token()) names.emplace_back(t);
    } else if (key == "SIZE") {
      header.sizes = integers(line, "SIZE", 1, 8);
    } else if (key == "TYPE") {
      for (std::string_view t = line.token(); !t.empty(); t = line.token()) {
        if (t.size() != 1) line.fail("PCD TYPE must be F, I or U, not '" + std::string(t) + "'");
        header.types.push_back(t.front());
      }
    } else if (key == "COUNT") {
      // A field of more than 2^20 values per point is not a point attribute; it also keeps
      // SIZE x COUNT x fields far from overflowing.
      header.counts = integers(line, "COUNT", 1, 1 << 20);
    } else if (key == "WIDTH") {
      header.width = line.readInt("WIDTH");
    } else if (key == "HEIGHT") {
      header.height = line.readInt("HEIGHT");
    } else if (key == "POINTS") {
      header.points = line.readInt("POINTS");
    } else if (key == "DATA") {
      const std::string_view kind = line.requireToken("DATA kind");
      if (kind == "ascii") {
        header.data = PcdData::Ascii;
      } else if (kind == "binary") {
        header.data = PcdData::Binary;
      } else if (kind == "binary_compressed") {
        header.data = PcdData::BinaryCompressed;
      } else {
        line.fail("unknown PCD DATA kind '" + std::string(kind.substr(0, 40)) + "'");
      }
      break;
    } else {
      line.fail("not a PCD file (unknown header line '" + std::string(key.substr(0, 20)) + "')");
    }
  }

  if (names.empty()) cursor.fail("PCD header has no FIELDS");
  if (header.counts.empty()) header.counts.assign(names.size(), 1);
  if (header.sizes.size() != names.size() || header.types.size() != names.size() ||
      header.counts.size() != names.size()) {
    cursor.fail("PCD header: FIELDS, SIZE, TYPE and COUNT have different lengths");
  }
  constexpr std::int64_t kMaxUInt32 = std::numeric_limits<std::uint32_t>::max();
  if (header.width < 0 || header.width > kMaxUInt32 || header.height < 0 ||
      header.height > kMaxUInt32) {
    cursor.fail("PCD WIDTH or HEIGHT is missing or out of range");
  }
  const std::int64_t grid = cursor.product(header.width, header.height, "WIDTH x HEIGHT");
  if (header.points < 0) header.points = grid;
  if (header.points != grid) {
    cursor.fail("PCD POINTS " + std::to_string(header.points) +
                " is not WIDTH x HEIGHT = " + std::to_string(grid));
  }
  if (header.points == 0) cursor.fail("PCD file has no points");

  std::int64_t offset = 0;
  for (std::size_t i = 0; i < names.size(); ++i) {
    pcl::PCLPointField field;
    field.name = names[i];
    field.offset = static_cast<std::uint32_t>(offset);
    field.datatype = pcdDatatype(header.types[i], header.sizes[i], cursor);
    field.count = static_cast<std::uint32_t>(header.counts[i]);
    header.fields.push_back(field);
    offset += header.sizes[i] * header.counts[i];  // each term <= 2^23: no overflow
    if (offset > kMaxUInt32) cursor.fail("PCD point size exceeds 4 GiB");
  }
  header.point_size = offset;
  return header;
}

void readAscii(ByteCursor& cursor, const PcdHeader& header, pcl::PCLPointCloud2& cloud) {
  std::int64_t point = 0;
  while (point < header.points) {
    if (cursor.atEnd()) cursor.fail("PCD data has fewer rows than POINTS (truncated?)");
    ByteCursor line = cursor.within(cursor.line());
    if (line.lineEnded()) continue;  // blank line
    std::uint8_t* dst = cloud.data.data() + point * cloud.point_step;
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
      const pcl::PCLPointField& field = header.fields[f];
      for (std::uint32_t c = 0; c < field.count; ++c) {
        line.storeAs(field.datatype, line.readDouble("PCD value"),
                     dst + field.offset + c * header.sizes[f], "the PCD field type");
      }
    }
    if (!line.token().empty()) line.fail("PCD row has more values than FIELDS x COUNT");
    ++point;
  }
}

// binary_compressed: two uint32 sizes, then LZF data that decompress to one array per field
// (padding fields "_" are not stored).
void readCompressed(ByteCursor& cursor, const PcdHeader& header, pcl::PCLPointCloud2& cloud) {
  const auto compressed = cursor.readBinary<std::uint32_t>(ByteOrder::Little, "compressed size");
  const auto uncompressed =
      cursor.readBinary<std::uint32_t>(ByteOrder::Little, "uncompressed size");
  std::uint64_t expected = 0;
  for (std::size_t f = 0; f < header.fields.size(); ++f) {
    if (header.fields[f].name != "_")
      expected += static_cast<std::uint64_t>(header.sizes[f] * header.counts[f]) *
                  static_cast<std::uint64_t>(header.points);
  }
  if (uncompressed != expected) {
    cursor.fail("PCD uncompressed size " + std::to_string(uncompressed) +
                " is not POINTS x point size = " + std::to_string(expected));
  }
  const char* packed = cursor.take(compressed, "compressed PCD data");
  if (compressed == 0) cursor.fail("PCD compressed data is empty");
  std::vector<char> unpacked(uncompressed);
  if (uncompressed > 0 &&
      lzf_decompress(packed, compressed, unpacked.data(), uncompressed) != uncompressed) {
    cursor.fail("PCD compressed data is corrupt");
  }
  const char* src = unpacked.data();
  for (std::size_t f = 0; f < header.fields.size(); ++f) {
    if (header.fields[f].name == "_") continue;
    const std::size_t size = static_cast<std::size_t>(header.sizes[f] * header.counts[f]);
    for (std::int64_t i = 0; i < header.points; ++i, src += size) {
      std::memcpy(cloud.data.data() + i * cloud.point_step + header.fields[f].offset, src, size);
    }
  }
}

}  // namespace

namespace {

// The header with WIDTH, HEIGHT and POINTS set for a piece of `count` points.
std::string pcdHeaderFor(const std::string& header, std::int64_t count) {
  return editLines(
      header,
      [](std::string& line, std::int64_t n) {
        const std::string key = line.substr(0, line.find(' '));
        if (key == "WIDTH" || key == "POINTS") line = key + " " + std::to_string(n);
        if (key == "HEIGHT") line = "HEIGHT 1";
      },
      count);
}

}  // namespace

BinaryCloudLayout pcdBinaryLayout(std::string_view head) {
  ByteCursor cursor(head);
  const PcdHeader header = parseHeader(cursor);
  if (header.data != PcdData::Binary) {
    cursor.fail("only an uncompressed binary PCD (DATA binary) is read a piece at a time");
  }
  BinaryCloudLayout layout;
  layout.header_bytes = static_cast<std::int64_t>(cursor.position());
  layout.points = header.points;
  layout.point_bytes = header.point_size;
  layout.width = static_cast<std::uint32_t>(header.width);
  layout.height = static_cast<std::uint32_t>(header.height);
  layout.sensor_pose = header.sensor_pose;
  layout.header = std::string(head.substr(0, cursor.position()));
  layout.header_for = pcdHeaderFor;
  return layout;
}

pcl::PolygonMesh parsePCD(std::string_view data, SensorPose* sensor_pose,
                          std::size_t spare_point_bytes) {
  ByteCursor cursor(data);
  const PcdHeader header = parseHeader(cursor);
  if (sensor_pose) *sensor_pose = header.sensor_pose;
  const std::int64_t point_size = header.point_size;
  const std::int64_t remaining = static_cast<std::int64_t>(cursor.remaining());
  // What the body must hold at least: all of it (binary), a digit and a separator per value
  // (ascii), or what LZF (at most ~90x expansion) can give. Checked before allocating anything,
  // so that a small file never costs more than a small multiple of its size.
  const std::int64_t bytes = cursor.product(point_size, header.points, "POINTS x point size");
  std::int64_t values_per_point = 0;
  for (const std::int64_t count : header.counts) values_per_point += count;
  if ((header.data == PcdData::Binary && bytes > remaining) ||
      (header.data == PcdData::Ascii &&
       cursor.product(values_per_point, header.points, "POINTS x values") > remaining / 2) ||
      (header.data == PcdData::BinaryCompressed && bytes / 128 > remaining)) {
    cursor.fail("PCD data shorter than POINTS x point size (truncated?)");
  }
  if (bytes > std::numeric_limits<std::uint32_t>::max()) {
    cursor.fail("PCD cloud too large for a pcl::PCLPointCloud2 (4 GiB)");
  }

  pcl::PolygonMesh mesh;
  pcl::PCLPointCloud2& cloud = mesh.cloud;
  cloud.fields = header.fields;
  cloud.width = static_cast<std::uint32_t>(header.width);
  cloud.height = static_cast<std::uint32_t>(header.height);
  cloud.point_step = static_cast<std::uint32_t>(point_size);
  cloud.row_step = static_cast<std::uint32_t>(point_size * header.width);
  cloud.is_dense = false;  // unknown until checked; consumers test finiteness themselves
  // The room asked for, at most four times the points' own bytes (a compressed file's claimed
  // size is itself a multiple of the file's).
  const std::size_t spare =
      std::min<std::size_t>(spare_point_bytes, 4 * static_cast<std::size_t>(point_size));
  if (spare > 0)
    cloud.data.reserve(static_cast<std::size_t>(bytes) + spare * cloud.width * cloud.height);
  switch (header.data) {
    case PcdData::Ascii:
      cloud.data.resize(static_cast<std::size_t>(bytes));
      readAscii(cursor, header, cloud);
      break;
    case PcdData::Binary: {
      const char* body = cursor.take(static_cast<std::size_t>(bytes), "data");
      cloud.data.assign(body, body + bytes);
      break;
    }
    case PcdData::BinaryCompressed:
      cloud.data.resize(static_cast<std::size_t>(bytes));
      readCompressed(cursor, header, cloud);
      break;
  }
  return mesh;
}

namespace {

char pcdType(std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::INT16:
    case pcl::PCLPointField::INT32:
    case pcl::PCLPointField::INT64:
      return 'I';
    case pcl::PCLPointField::FLOAT32:
    case pcl::PCLPointField::FLOAT64:
      return 'F';
    default:
      return 'U';
  }
}

std::string pcdHeader(const std::vector<const pcl::PCLPointField*>& fields, std::int64_t width,
                      std::int64_t height, const SensorPose& sensor_pose, const char* data) {
  std::string header = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS";
  for (const auto* f : fields) header += " " + f->name;
  header += "\nSIZE";
  for (const auto* f : fields) header += " " + std::to_string(pcl::getFieldSize(f->datatype));
  header += "\nTYPE";
  for (const auto* f : fields) header += std::string(" ") + pcdType(f->datatype);
  header += "\nCOUNT";
  for (const auto* f : fields) header += " " + std::to_string(std::max<std::uint32_t>(f->count, 1));
  std::ostringstream viewpoint;
  viewpoint.imbue(std::locale::classic());
  viewpoint << std::setprecision(17) << sensor_pose.origin.x() << ' ' << sensor_pose.origin.y()
            << ' ' << sensor_pose.origin.z() << ' ' << sensor_pose.orientation.w() << ' '
            << sensor_pose.orientation.x() << ' ' << sensor_pose.orientation.y() << ' '
            << sensor_pose.orientation.z();
  header += "\nWIDTH " + std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
            "\nVIEWPOINT " + viewpoint.str() + "\nPOINTS " + std::to_string(width * height) +
            "\nDATA " + data + "\n";
  return header;
}

}  // namespace

std::string binaryPCDHeader(const pcl::PCLPointCloud2& cloud, std::int64_t width,
                            std::int64_t height, const SensorPose& sensor_pose) {
  std::vector<const pcl::PCLPointField*> fields;
  for (const auto& f : cloud.fields) fields.push_back(&f);
  return pcdHeader(fields, width, height, sensor_pose, "binary");
}

// binary_compressed, as PCL's tools write it: the fields one after the other (each as an array
// over all points), LZF-compressed. Padding fields ("_") carry nothing and are left out. The
// planar bytes are compressed a block at a time and written as they come: blocks compressed
// apart make one LZF stream (each starts with a literal run and refers back only into itself),
// which PCL's reader decompresses in one call; so only two blocks are held, not the planar copy
// and its compression beside the cloud (2.5 bytes of memory for each byte of the file).
void writePCD(std::ostream& out, const pcl::PCLPointCloud2& cloud, const SensorPose& sensor_pose) {
  std::vector<const pcl::PCLPointField*> fields;
  for (const auto& f : cloud.fields) {
    if (f.name != "_" && pcl::getFieldSize(f.datatype) > 0) fields.push_back(&f);
  }
  if (fields.empty()) throw FileFormatException("the cloud has no fields to write");
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  std::uint64_t planar_size = 0;
  for (const auto* f : fields)
    planar_size += static_cast<std::uint64_t>(pcl::getFieldSize(f->datatype)) *
                   std::max<std::uint32_t>(f->count, 1) * n;
  if (planar_size > std::numeric_limits<std::uint32_t>::max() / 2) {
    throw FileFormatException("cloud too large for a compressed PCD file");
  }
  out << pcdHeader(fields, cloud.width, cloud.height, sensor_pose, "binary_compressed");
  const std::streampos sizes_at = out.tellp();
  out.write("\0\0\0\0\0\0\0\0", 8);  // the sizes, once known

  constexpr std::size_t kBlock = std::size_t{1} << 20;
  std::vector<char> planar(kBlock);
  // LZF may expand incompressible data slightly; PCL allows 1.5x as well.
  std::vector<char> packed(kBlock + kBlock / 2 + 64);
  std::size_t filled = 0;
  std::uint64_t packed_total = 0;
  const auto flush = [&] {
    if (filled == 0) return;
    const unsigned int size = lzf_compress(planar.data(), static_cast<unsigned int>(filled),
                                           packed.data(), static_cast<unsigned int>(packed.size()));
    if (size == 0) throw FileFormatException("LZF compression failed");
    out.write(packed.data(), size);
    packed_total += size;
    filled = 0;
  };
  // A value may span blocks (a field of a large COUNT is larger than one).
  const auto append = [&](const std::uint8_t* from, std::size_t size) {
    while (size > 0) {
      const std::size_t take = std::min(size, kBlock - filled);
      std::memcpy(planar.data() + filled, from, take);
      filled += take;
      from += take;
      size -= take;
      if (filled == kBlock) flush();
    }
  };
  for (const auto* f : fields) {
    const std::size_t size = pcl::getFieldSize(f->datatype) * std::max<std::uint32_t>(f->count, 1);
    for (std::size_t i = 0; i < n; ++i)
      append(cloud.data.data() + i * cloud.point_step + f->offset, size);
  }
  flush();
  const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(packed_total),
                                  static_cast<std::uint32_t>(planar_size)};
  out.seekp(sizes_at);
  out.write(reinterpret_cast<const char*>(sizes), 8);
  out.seekp(0, std::ios::end);
}

}  // namespace detail
}  // namespace pcl_ddg
