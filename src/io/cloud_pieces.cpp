#include "pcl_ddg/io/cloud_pieces.h"

#include <pcl/exceptions.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <optional>
#include <sstream>

#include "las_format.h"
#include "laz/laz_codec.h"
#include "loader_threads.h"
#include "mesh_formats.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/atomic_file.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace {

[[noreturn]] void failSystem(const std::string& what) {
  throw FileFormatException(what + ": " + std::strerror(errno));
}

template <typename T>
T getLE(const std::string& bytes, std::size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  return value;
}
template <typename T>
void putLE(std::string& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof(T));
}

/** Whether a LAS file's header and VLRs hold COPC's info VLR (its one EVLR is then the
 *  hierarchy, which no output keeps: las_plan.cpp). */
bool isCopcPrefix(const std::string& prefix) {
  const std::uint32_t vlrs = getLE<std::uint32_t>(prefix, 100);
  std::size_t at = getLE<std::uint16_t>(prefix, 94);
  for (std::uint32_t i = 0; i < vlrs && at + 54 <= prefix.size(); ++i) {
    if (prefix.compare(at + 2, 5, std::string("copc\0", 5)) == 0 &&
        getLE<std::uint16_t>(prefix, at + 18) == 1)
      return getLE<std::uint32_t>(prefix, 243) == 1;
    at += 54 + getLE<std::uint16_t>(prefix, at + 20);
  }
  return false;
}

bool declaresDoubleCoordinates(const pcl::PCLPointCloud2& cloud) {
  return std::any_of(cloud.fields.begin(), cloud.fields.end(), [](const pcl::PCLPointField& f) {
    return (f.name == "x" || f.name == "y" || f.name == "z") &&
           f.datatype == pcl::PCLPointField::FLOAT64;
  });
}

}  // namespace

// How a piece's file is made: the header rewritten for its count, and the parser of the whole.
struct CloudPieceReader::Format {
  bool las = false, pcd = false;
  std::string header;  // PCD/PLY: the header text; LAS: the header and VLRs
  std::string (*header_for)(const std::string&, std::int64_t) = nullptr;
  std::uint8_t las_minor = 0;
  bool las_legacy_count = false;
  /** A LAZ file: its chunks, and the records of the last run of chunks decoded (consecutive
   *  pieces often share a chunk). */
  std::optional<detail::LazChunkIndex> laz;
  std::size_t decoded_first = 0, decoded_last = 0;
  std::string decoded;  // empty: none yet

  std::string headerFor(std::int64_t count) const {
    if (!las) return header_for(header, count);
    // A LAS file of `count` of these records: no waveform data, no EVLRs.
    std::string out = header;
    if (las_legacy_count) putLE<std::uint32_t>(out, 107, static_cast<std::uint32_t>(count));
    if (las_minor >= 3) putLE<std::uint64_t>(out, 227, 0);
    if (las_minor >= 4) {
      putLE<std::uint64_t>(out, 235, 0);
      putLE<std::uint32_t>(out, 243, 0);
      putLE<std::uint64_t>(out, 247, static_cast<std::uint64_t>(count));
    }
    return out;
  }
};

CloudPieceReader::CloudPieceReader(const std::string& path)
    : path_(path), format_(std::make_unique<Format>()) {
  const std::string ext = fileExtension(path);
  if (ext != "pcd" && ext != "ply" && ext != "las" && ext != "laz") {
    throw FileFormatException(path +
                              ": only binary .pcd, binary .ply and .las clouds are read in pieces");
  }
  in_.open(path, std::ios::binary);
  if (!in_) failSystem(path);
  const auto size = static_cast<std::int64_t>(std::filesystem::file_size(path));
  if (ext == "las" || ext == "laz") {  // LAZ is told by its header, and refused there
    // The public header block (LAS 1.4: 375 bytes), then the header and VLRs up to the points.
    std::string head(static_cast<std::size_t>(std::min<std::int64_t>(375, size)), '\0');
    in_.read(head.data(), static_cast<std::streamsize>(head.size()));
    if (in_.gcount() < 227 || head.compare(0, 4, "LASF") != 0)
      throw FileFormatException(path + ": not a LAS file (no LASF signature)");
    Format& f = *format_;
    if (lasIsCompressed(head)) {
      // LAZ: its chunks found from the chunk table, the pieces' header that of the LAS file it
      // stands for, their records decoded chunk by chunk.
      try {
        f.laz = detail::indexLazChunks(
            [&](std::uint64_t offset, std::uint64_t count) { return readBytes(offset, count); },
            static_cast<std::uint64_t>(size));
      } catch (const pcl::PCLException& e) {
        throw FileFormatException(path + ": " + errorDescription(e));
      }
      if (getLE<std::uint8_t>(head, 25) >= 4 && head.size() >= 375 &&
          getLE<std::uint32_t>(head, 243) != 0 && !isCopcPrefix(f.laz->prefix))
        throw FileFormatException(path + ": a LAS file with EVLRs is not read in pieces");
      // Its header as the LAS file's (the prefix counts no points: the counts are the file's).
      const std::string counts = head;
      head = f.laz->las_prefix.substr(0, head.size());
      head.replace(107, 4, counts, 107, 4);
      if (head.size() >= 255) head.replace(247, 8, counts, 247, 8);
    }
    f.las = true;
    f.las_minor = static_cast<std::uint8_t>(head[25]);
    const auto point_offset = getLE<std::uint32_t>(head, 96);
    layout_.header_bytes = point_offset;
    layout_.point_bytes = getLE<std::uint16_t>(head, 105);
    f.las_legacy_count = getLE<std::uint32_t>(head, 107) != 0;
    layout_.points = getLE<std::uint32_t>(head, 107);
    if (f.las_minor >= 4 && head.size() >= 255) {
      layout_.points = static_cast<std::int64_t>(getLE<std::uint64_t>(head, 247));
      if (getLE<std::uint32_t>(head, 243) != 0)
        throw FileFormatException(path + ": a LAS file with EVLRs is not read in pieces");
    }
    if (f.laz) {
      f.header = f.laz->las_prefix;
    } else {
      if (point_offset > size || layout_.point_bytes == 0 || layout_.points < 0 ||
          (size - point_offset) / layout_.point_bytes < layout_.points)
        throw FileFormatException(path + ": shorter than its points (truncated?)");
      f.header = readBytes(0, point_offset);
    }
    layout_.width = static_cast<std::uint32_t>(layout_.points);
    layout_.height = 1;
    try {  // the layout, from the header and VLRs as a file of no points
      las_ = std::make_shared<const LasLayout>(detail::parseLAS(f.headerFor(0)).layout);
    } catch (const pcl::PCLException& e) {
      throw FileFormatException(path + ": " + errorDescription(e));
    }
    return;
  }
  // A header is read from the file's first 64 KiB, or 4 MiB when it is longer (many comments).
  detail::BinaryCloudLayout binary;
  for (const std::int64_t want : {std::int64_t{64} << 10, std::int64_t{4} << 20}) {
    std::string head(static_cast<std::size_t>(std::min(want, size)), '\0');
    in_.seekg(0);
    in_.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in_.gcount()));
    in_.clear();
    try {
      binary = ext == "pcd" ? detail::pcdBinaryLayout(head) : detail::plyBinaryLayout(head);
      break;
    } catch (const pcl::PCLException& e) {
      if (want < (std::int64_t{4} << 20) && size > want) continue;
      throw FileFormatException(path + ": " + errorDescription(e));
    }
  }
  if (binary.point_bytes <= 0 || (size - binary.header_bytes) / binary.point_bytes < binary.points)
    throw FileFormatException(path + ": shorter than its points (truncated?)");
  layout_.points = binary.points;
  layout_.header_bytes = binary.header_bytes;
  layout_.point_bytes = binary.point_bytes;
  layout_.width = binary.width;
  layout_.height = binary.height;
  layout_.sensor_pose = binary.sensor_pose;
  format_->header = std::move(binary.header);
  format_->header_for = binary.header_for;
  format_->pcd = ext == "pcd";
}

CloudPieceReader::~CloudPieceReader() = default;

const CloudFileLayout& CloudPieceReader::layout() const {
  return layout_;
}

const std::shared_ptr<const LasLayout>& CloudPieceReader::lasLayout() const {
  return las_;
}

CloudPiece CloudPieceReader::read(std::int64_t first, std::int64_t count) {
  if (first < 0 || count < 0 || first > layout_.points || count > layout_.points - first) {
    throw pcl::BadArgumentException(path_ + ": points " + std::to_string(first) + ".." +
                                    std::to_string(first + count) + " are not in the file");
  }
  std::string file = format_->headerFor(count);
  const auto bytes = static_cast<std::size_t>(count * layout_.point_bytes);
  if (format_->laz) {
    file += lazRecords(first, count);
  } else {
    file += readBytes(
        static_cast<std::uint64_t>(layout_.header_bytes + first * layout_.point_bytes), bytes);
  }
  CloudPiece piece;
  try {
    if (format_->las) {
      detail::LasCloud las = detail::parseLAS(file);
      piece.cloud = std::move(las.mesh.cloud);
      piece.positions = std::move(las.positions);
      piece.coordinate_precision = FieldPrecision::Double;  // X * scale + offset
      return piece;
    }
    piece.cloud = (format_->pcd ? detail::parsePCD(file) : detail::parsePLY(file)).cloud;
  } catch (const pcl::PCLException& e) {
    throw FileFormatException(path_ + ": " + errorDescription(e));
  }
  piece.positions = vertexPositions(piece.cloud, NonFinitePolicy::Keep);
  if (declaresDoubleCoordinates(piece.cloud)) piece.coordinate_precision = FieldPrecision::Double;
  return piece;
}

std::vector<std::pair<std::int64_t, std::int64_t>> CloudPieceReader::lazChunks() const {
  std::vector<std::pair<std::int64_t, std::int64_t>> chunks;
  if (format_->laz)
    for (const auto& c : format_->laz->chunks)
      chunks.emplace_back(static_cast<std::int64_t>(c.first_point),
                          static_cast<std::int64_t>(c.points));
  return chunks;
}

std::string CloudPieceReader::readBytes(std::uint64_t offset, std::uint64_t count) {
  std::string bytes(static_cast<std::size_t>(count), '\0');
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(offset));
  in_.read(bytes.data(), static_cast<std::streamsize>(count));
  if (in_.gcount() != static_cast<std::streamsize>(count))
    throw FileFormatException(path_ + ": cannot read bytes " + std::to_string(offset) + ".." +
                              std::to_string(offset + count) + " (truncated?)");
  return bytes;
}

std::string CloudPieceReader::lazRecords(std::int64_t first, std::int64_t count) {
  Format& f = *format_;
  const auto& chunks = f.laz->chunks;
  if (count == 0) return {};
  // The chunks holding the first and the last point.
  const auto chunkOf = [&](std::uint64_t point) {
    return static_cast<std::size_t>(
        std::upper_bound(chunks.begin(), chunks.end(), point,
                         [](std::uint64_t p, const auto& c) { return p < c.first_point; }) -
        chunks.begin() - 1);
  };
  const std::size_t a = chunkOf(static_cast<std::uint64_t>(first));
  const std::size_t b = chunkOf(static_cast<std::uint64_t>(first + count - 1));
  if (f.decoded.empty() || a < f.decoded_first || b > f.decoded_last) {
    const std::string bytes = readBytes(chunks[a].begin, chunks[b].end - chunks[a].begin);
    try {
      f.decoded = detail::decodeLazChunks(*f.laz, a, b, bytes, detail::loaderThreads());
    } catch (const pcl::PCLException& e) {
      throw FileFormatException(path_ + ": " + errorDescription(e));
    }
    f.decoded_first = a;
    f.decoded_last = b;
  }
  const std::uint64_t skip =
      static_cast<std::uint64_t>(first) - chunks[f.decoded_first].first_point;
  return f.decoded.substr(static_cast<std::size_t>(skip * layout_.point_bytes),
                          static_cast<std::size_t>(count * layout_.point_bytes));
}

/** A LAS output written in pieces; a LAZ one is that LAS file, next to it (removed whatever
 *  happens, Ctrl-C included: an uncommitted AtomicFile), compressed at close a chunk at a time. */
struct CloudPieceWriter::Las {
  Las(const std::string& path, const LasLayout& layout, bool compressed)
      : laz_path(compressed ? path : std::string()),
        records(compressed ? std::make_unique<AtomicFile>(path + ".las") : nullptr),
        writer(records ? records->temporaryPath() : path, layout) {}

  void close() {
    writer.close();
    if (!records) return;
    std::ifstream las(records->temporaryPath(), std::ios::binary);
    std::ofstream laz(laz_path, std::ios::binary | std::ios::trunc);
    if (!las || !laz) failSystem("cannot write " + laz_path);
    const auto size =
        static_cast<std::uint64_t>(std::filesystem::file_size(records->temporaryPath()));
    detail::lasToLaz(
        [&](std::uint64_t offset, std::uint64_t count) {
          std::string bytes(static_cast<std::size_t>(count), '\0');
          las.seekg(static_cast<std::streamoff>(offset));
          las.read(bytes.data(), static_cast<std::streamsize>(count));
          if (las.gcount() != static_cast<std::streamsize>(count))
            failSystem("cannot read back " + records->temporaryPath());
          return bytes;
        },
        size,
        {[&](std::string_view bytes) {
           laz.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
         },
         [&](std::uint64_t at, std::string_view bytes) {
           const std::streampos end = laz.tellp();
           laz.seekp(static_cast<std::streamoff>(at));
           laz.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
           laz.seekp(end);
         }});
    laz.close();
    if (!laz) failSystem("cannot write " + laz_path);
  }

  std::string laz_path;                 // empty: a .las output
  std::unique_ptr<AtomicFile> records;  // a .laz output's LAS records, never committed
  detail::LasPieceWriter writer;
};

CloudPieceWriter::CloudPieceWriter(const std::string& path, const std::string& format,
                                   std::int64_t points, std::uint32_t width, std::uint32_t height,
                                   const SensorPose& sensor_pose,
                                   const std::shared_ptr<const LasLayout>& las)
    : ply_(format == "ply"),
      points_(points),
      width_(width),
      height_(height),
      sensor_pose_(sensor_pose) {
  if (format != "ply" && format != "pcd" && format != "las" && format != "laz")
    throw FileFormatException(path + ": pieces are written as .ply, .pcd, .las or .laz");
  if (format == "las" || format == "laz") {
    if (!las) {
      throw FileFormatException("a ." + format +
                                " output written in pieces keeps a LAS input's layout: the input "
                                "is not LAS");
    }
    if (format == "laz" && !lazCompressible(las->point_format))
      throw FileFormatException("point format " + std::to_string(las->point_format) +
                                " cannot be written as LAZ (formats 0-3 and 6-8 can): write .las");
    las_ = std::make_unique<Las>(path, *las, format == "laz");
    return;
  }
  out_.open(path, std::ios::binary);
  if (!out_) failSystem("cannot write " + path);
}

CloudPieceWriter::~CloudPieceWriter() = default;

void CloudPieceWriter::write(pcl::PCLPointCloud2& piece) {
  if (las_) {
    las_->writer.write(piece);
    return;
  }
  // Colours in the format's layout and no padding in a PCD, as saveMesh writes them.
  const ColorLayout colors = ply_ ? ColorLayout::Channels : ColorLayout::PackedRGB;
  const auto current = vertexColorLayout(piece);
  if (current && *current != colors) setVertexColors(piece, vertexColors(piece), colors);
  if (!ply_) {
    while (removeVertexField(piece, "_")) {
    }
  }
  const auto same = [](const pcl::PCLPointField& a, const pcl::PCLPointField& b) {
    return a.name == b.name && a.offset == b.offset && a.datatype == b.datatype &&
           a.count == b.count;
  };
  if (first_) {
    fields_ = piece.fields;
    point_step_ = piece.point_step;
  } else if (piece.point_step != point_step_ ||
             !std::equal(piece.fields.begin(), piece.fields.end(), fields_.begin(), fields_.end(),
                         same)) {
    throw FileFormatException("a piece's fields differ from the first piece's");
  }
  if (!ply_) {
    if (first_) out_ << detail::binaryPCDHeader(piece, width_, height_, sensor_pose_);
    out_.write(reinterpret_cast<const char*>(piece.data.data()),
               static_cast<std::streamsize>(piece.data.size()));
  } else {
    pcl::PolygonMesh mesh;
    mesh.cloud = piece;
    std::ostringstream encoded;
    detail::writePLY(encoded, mesh, PlyEncoding::Binary);
    const std::string bytes = encoded.str();
    const std::size_t body = bytes.find("end_header\n") + 11;
    if (first_) out_ << detail::plyHeaderWithVertices(bytes.substr(0, body), points_);
    out_.write(bytes.data() + body, static_cast<std::streamsize>(bytes.size() - body));
  }
  first_ = false;
  if (!out_) failSystem("cannot write the output");
}

void CloudPieceWriter::close() {
  if (las_) {
    las_->close();
    return;
  }
  out_.close();
  if (!out_) failSystem("cannot write the output");
}

}  // namespace pcl_ddg
