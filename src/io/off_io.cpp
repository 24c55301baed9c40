// Object File Format (Geomview): "OFF" header, counts, vertices, faces. Colour and normal variants
// (COFF, NOFF, CNOFF) carry extra values per line, which are ignored; "OFF BINARY" in either byte
// order and either face layout (Geomview's, pmp-library's).
#include <algorithm>
#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "byte_cursor.h"
#include "loader_threads.h"
#include "mesh_formats.h"
#include "xyz_cloud.h"

namespace pcl_ddg {
namespace detail {
namespace {

// The next line that is neither blank nor a comment.
std::string_view contentLine(ByteCursor& cursor, const char* what) {
  for (;;) {
    if (cursor.atEnd()) cursor.fail(std::string("unexpected end of file while reading ") + what);
    std::string_view text = cursor.line();
    const std::size_t hash = text.find('#');
    if (hash != std::string_view::npos) text = text.substr(0, hash);
    if (text.find_first_not_of(" \t\r") != std::string_view::npos) return text;
  }
}

// Binary OFF: after the header line three int32 counts (vertices, faces, edges), each vertex as
// three float32, then the faces. Two face layouts are in use: Geomview's spec ends each face with
// a colour count c (0 to 4) and c float32 values, big-endian; pmp-library's write_off writes
// `n i0 … i(n−1)` alone, in host order (little-endian). Neither the header nor the counts tell
// them apart, so each layout is walked over the face sizes and the one that ends where the file
// does is read (trailing whitespace allowed: CGAL's writer ends with a newline). Should two fit,
// the first tried wins: big-endian (the spec's) before little-endian, Geomview's before pmp's.
enum class FaceLayout { Geomview, Pmp };

const char* name(ByteOrder order) {
  return order == ByteOrder::Big ? "big-endian" : "little-endian";
}
const char* name(FaceLayout faces) {
  return faces == FaceLayout::Geomview ? "Geomview" : "pmp-library";
}

// A binary file has no lines: its errors name the byte.
std::string atByte(std::size_t offset, const std::string& message) {
  return "byte offset " + std::to_string(offset) + ": " + message;
}

struct BinaryOffCounts {
  std::int64_t vertices = 0;
  std::int64_t faces = 0;
};

// The counts read in `order` (cursor at the first), or nothing when they are negative or more
// than the bytes after them hold (a vertex takes 12, a face at least 4).
std::optional<BinaryOffCounts> countsIn(ByteCursor probe, ByteOrder order) {
  if (probe.remaining() < 12) return std::nullopt;
  BinaryOffCounts counts;
  counts.vertices = probe.readBinary<std::int32_t>(order, "vertex count");
  counts.faces = probe.readBinary<std::int32_t>(order, "face count");
  probe.skip(4, "edge count");
  const auto left = static_cast<std::int64_t>(probe.remaining());
  if (counts.vertices < 0 || counts.faces < 0 || counts.vertices > left / 12 ||
      counts.faces > (left - 12 * counts.vertices) / 4) {
    return std::nullopt;
  }
  return counts;
}

// Empty when the faces in this layout end where the data does (cursor at the first count);
// otherwise where and why they do not. Nothing is allocated: only the sizes are read.
std::string misfit(ByteCursor probe, ByteOrder order, FaceLayout faces, BinaryOffCounts counts) {
  const auto next = [&] { return probe.readBinary<std::int32_t>(order, "binary OFF"); };
  probe.skip(12 + 12 * static_cast<std::size_t>(counts.vertices), "vertices");  // fits: countsIn
  for (std::int64_t f = 0; f < counts.faces; ++f) {
    const auto face = [&] {
      return "face " + std::to_string(f) + " of " + std::to_string(counts.faces);
    };
    if (probe.remaining() < 4) return atByte(probe.position(), "the file ends before " + face());
    const std::size_t size_at = probe.position();
    const std::int32_t n = next();
    if (n < 0) return atByte(size_at, face() + " has a negative size");
    if (static_cast<std::size_t>(n) > probe.remaining() / 4) {
      return atByte(size_at, face() + " has " + std::to_string(n) + " corners, more than the " +
                                 std::to_string(probe.remaining()) + " bytes left hold");
    }
    probe.skip(4 * static_cast<std::size_t>(n), "face");
    if (faces == FaceLayout::Pmp) continue;
    if (probe.remaining() < 4) {
      return atByte(probe.position(), "the file ends before the colour count of " + face());
    }
    const std::size_t colour_at = probe.position();
    const std::int32_t colour_values = next();
    if (colour_values < 0 || colour_values > 4) {
      return atByte(colour_at,
                    face() + " has colour count " + std::to_string(colour_values) + ", not 0 to 4");
    }
    if (4 * static_cast<std::size_t>(colour_values) > probe.remaining()) {
      return atByte(colour_at, "the file ends in the colour of " + face());
    }
    probe.skip(4 * static_cast<std::size_t>(colour_values), "face colour");
  }
  const std::size_t end = probe.position();
  const std::size_t rest_size = probe.remaining();
  const std::string_view rest(probe.take(rest_size, "trailer"), rest_size);
  if (rest.find_first_not_of(" \t\r\n") == std::string_view::npos) return {};
  return atByte(end, std::to_string(rest.size()) + " bytes left after the last face");
}

// Reads a layout that misfit() accepted: every read stays within the data.
pcl::PolygonMesh readBinaryOFF(ByteCursor& cursor, ByteOrder order, FaceLayout faces,
                               BinaryOffCounts counts) {
  const auto next = [&] { return cursor.readBinary<std::int32_t>(order, "binary OFF"); };
  cursor.skip(12, "counts");
  std::vector<double> xyz(3 * static_cast<std::size_t>(counts.vertices));
  for (double& v : xyz) v = cursor.readBinary<float>(order, "vertex");
  pcl::PolygonMesh mesh;
  mesh.cloud = makeXYZCloud(xyz);
  mesh.polygons.resize(static_cast<std::size_t>(counts.faces));
  for (auto& polygon : mesh.polygons) {
    polygon.vertices.resize(static_cast<std::size_t>(next()));
    for (auto& corner : polygon.vertices) corner = cornerIndex(next());
    if (faces == FaceLayout::Geomview) cursor.skip(4 * static_cast<std::size_t>(next()), "colour");
  }
  return mesh;
}

pcl::PolygonMesh parseBinaryOFF(ByteCursor& cursor) {
  std::string misfits;
  bool counts_fit = false;
  for (const ByteOrder order : {ByteOrder::Big, ByteOrder::Little}) {
    const std::optional<BinaryOffCounts> counts = countsIn(cursor, order);
    if (!counts) {
      misfits += std::string(misfits.empty() ? ": " : "; ") + name(order) +
                 ": the counts do not fit the file";
      continue;
    }
    counts_fit = true;
    for (const FaceLayout faces : {FaceLayout::Geomview, FaceLayout::Pmp}) {
      const std::string why = misfit(cursor, order, faces, *counts);
      if (why.empty()) return readBinaryOFF(cursor, order, faces, *counts);
      misfits += std::string(misfits.empty() ? ": " : "; ") + name(faces) + " " + name(order) +
                 " at " + why;
    }
  }
  if (!counts_fit) {
    throw FileFormatException(
        atByte(cursor.position(),
               "binary OFF counts fit the file in neither byte order (truncated or not OFF?)"));
  }
  throw FileFormatException(
      "binary OFF fits neither Geomview's face layout (n i0 .. i(n-1) c colour[c]) nor "
      "pmp-library's (n i0 .. i(n-1)) in either byte order" +
      misfits);
}

}  // namespace

pcl::PolygonMesh parseOFF(std::string_view data, FaceRows* rows) {
  ByteCursor cursor(data);
  const std::string_view magic = cursor.token();
  if (magic.size() < 3 || magic.substr(magic.size() - 3) != "OFF") {
    cursor.fail("not an OFF file (no OFF header)");
  }
  if (!cursor.lineEnded()) {
    if (cursor.token() != "BINARY") cursor.fail("unexpected text after the OFF header");
    // C/N/ST add per-vertex values that would be taken for coordinates: refused, never misread.
    if (magic != "OFF")
      cursor.fail("binary " + std::string(magic) + " is not supported (only OFF)");
    cursor.line();
    return parseBinaryOFF(cursor);
  }
  cursor.line();

  ByteCursor counts = cursor.within(contentLine(cursor, "counts"));
  const std::int64_t num_vertices = counts.readInt("vertex count");
  const std::int64_t num_faces = counts.readInt("face count");
  if (num_vertices < 0 || num_faces < 0) cursor.fail("negative vertex or face count");
  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line 2 ("0\n"): a count beyond
  // that is a lie, refused before anything is allocated.
  const auto remaining = static_cast<std::int64_t>(cursor.remaining());
  if (num_vertices > remaining / 6 || num_faces > remaining / 2) {
    cursor.fail("vertex or face count larger than the file can hold (truncated?)");
  }

  pcl::PolygonMesh mesh;
  mesh.cloud = doubleXYZCloud(static_cast<std::size_t>(num_vertices));
  // Rows asked for: triangles go straight into them (no heap vector per face); a face of another
  // size is still read and checked, and the faces are then read again as polygons.
  std::vector<std::int32_t> triangles(rows ? 3 * static_cast<std::size_t>(num_faces) : 0);
  std::atomic<bool> not_triangles{false};
  bool as_rows = rows != nullptr;
  if (!as_rows) mesh.polygons.resize(static_cast<std::size_t>(num_faces));
  // The content lines a block at a time (cheap: a scan for newlines), each block's lines then
  // parsed in parallel: a block's table of lines, not the whole file's (55 MB for 3.5M lines).
  std::vector<std::string_view> lines;
  std::int64_t first_line = 0;
  const auto parseLine = [&](std::int64_t i) {
    ByteCursor values = cursor.within(lines[static_cast<std::size_t>(i - first_line)]);
    if (i < num_vertices) {
      for (int d = 0; d < 3; ++d)
        setXYZ(mesh.cloud, static_cast<std::size_t>(i), d, values.readDouble("vertex coordinate"));
      return;
    }
    const auto face = static_cast<std::size_t>(i - num_vertices);
    const std::int64_t n = values.readInt("face size");
    if (n < 0 || n > static_cast<std::int64_t>(values.remaining())) {
      values.fail("face size " + std::to_string(n) + " does not fit its line");
    }
    if (as_rows && n == 3) {
      for (int k = 0; k < 3; ++k)
        triangles[3 * face + k] = cornerIndex(values.readInt("face index"));
    } else if (as_rows) {
      not_triangles = true;
      for (std::int64_t k = 0; k < n; ++k) cornerIndex(values.readInt("face index"));
    } else {
      auto& polygon = mesh.polygons[face];
      polygon.vertices.resize(static_cast<std::size_t>(n));
      for (auto& corner : polygon.vertices) corner = cornerIndex(values.readInt("face index"));
    }
  };
  // The first error by line order is the one reported: the blocks go in order, and each
  // thread's lines are contiguous.
  constexpr std::int64_t kLinesPerThread = 16384;  // small files: no thread started
  constexpr std::int64_t kLinesPerBlock = 32 * kLinesPerThread;
  std::size_t faces_start = cursor.position();
  const auto parseLines = [&](std::int64_t from, std::int64_t to) {
    for (first_line = from; first_line < to; first_line += kLinesPerBlock) {
      const std::int64_t count = std::min(kLinesPerBlock, to - first_line);
      lines.clear();
      for (std::int64_t i = first_line; i < first_line + count; ++i) {
        if (i == num_vertices) faces_start = cursor.position();
        lines.push_back(contentLine(cursor, i < num_vertices ? "vertices" : "faces"));
      }
      parallelForInLoader(count, kLinesPerThread,
                          [&](std::int64_t i) { parseLine(first_line + i); });
    }
  };
  parseLines(0, num_vertices + num_faces);
  if (as_rows && !not_triangles) {
    rows->indices = std::move(triangles);
    rows->corners = 3;
  } else if (as_rows) {  // checked above: read again, as polygons
    std::vector<std::int32_t>().swap(triangles);
    as_rows = false;
    mesh.polygons.resize(static_cast<std::size_t>(num_faces));
    cursor.seek(faces_start);
    parseLines(num_vertices, num_vertices + num_faces);
  }
  narrowXYZCloud(mesh.cloud);
  return mesh;
}

}  // namespace detail
}  // namespace pcl_ddg
