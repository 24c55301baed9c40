// Object File Format (Geomview): "OFF" header, counts, vertices, faces. Colour and normal variants
// (COFF, NOFF, CNOFF) carry extra values per line, which are ignored; "OFF BINARY" in either byte
// order.
#include <algorithm>
#include <vector>

#include "byte_cursor.h"
#include "formats.h"
#include "loader_threads.h"
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

// Binary OFF exists in both byte orders: Geomview's spec says big-endian, pmp-library writes the
// host's (little-endian). The order is the one whose reading of the three counts fits the file:
// every vertex takes 12 bytes and every face at least 8 (its size and its colour count).
ByteOrder binaryOffByteOrder(const ByteCursor& cursor) {
  const auto fits = [&](ByteOrder order) {
    ByteCursor probe = cursor;
    std::int64_t counts[3];
    for (std::int64_t& n : counts) {
      if (probe.remaining() < 4) return false;
      n = probe.readBinary<std::int32_t>(order, "count");
      if (n < 0) return false;
    }
    return 12 * counts[0] + 8 * counts[1] <= static_cast<std::int64_t>(probe.remaining());
  };
  if (fits(ByteOrder::Big)) return ByteOrder::Big;
  if (fits(ByteOrder::Little)) return ByteOrder::Little;
  cursor.fail("binary OFF counts fit the file in neither byte order (truncated or not OFF?)");
}

pcl::PolygonMesh parseBinaryOFF(ByteCursor& cursor) {
  const ByteOrder order = binaryOffByteOrder(cursor);
  // A count of n items of at least `bytes` each, which the remaining data must be able to hold.
  const auto read_count = [&](const char* what, std::size_t bytes) {
    const std::int32_t n = cursor.readBinary<std::int32_t>(order, what);
    if (n < 0) cursor.fail(std::string("negative ") + what);
    if (static_cast<std::size_t>(n) > cursor.remaining() / bytes) {
      cursor.fail(std::string(what) + " " + std::to_string(n) + " is more than the file holds");
    }
    return n;
  };
  const std::int32_t num_vertices = cursor.readBinary<std::int32_t>(order, "vertex count");
  const std::int32_t num_faces = cursor.readBinary<std::int32_t>(order, "face count");
  cursor.skip(4, "edge count");
  std::vector<double> xyz(3 * static_cast<std::size_t>(num_vertices));  // fits: checked above
  for (double& v : xyz) v = cursor.readBinary<float>(order, "vertex");
  pcl::PolygonMesh mesh;
  mesh.cloud = makeXYZCloud(xyz);
  mesh.polygons.resize(static_cast<std::size_t>(num_faces));
  for (auto& polygon : mesh.polygons) {
    const std::int32_t n = read_count("face size", 4);
    polygon.vertices.resize(static_cast<std::size_t>(n));
    for (auto& corner : polygon.vertices) {
      corner = cornerIndex(cursor.readBinary<std::int32_t>(order, "face"));
    }
    const std::int32_t colour_values = read_count("face colour count", 4);
    cursor.skip(4 * static_cast<std::size_t>(colour_values), "face colour");
  }
  return mesh;
}

}  // namespace

pcl::PolygonMesh parseOFF(std::string_view data) {
  ByteCursor cursor(data);
  const std::string_view magic = cursor.token();
  if (magic.size() < 3 || magic.substr(magic.size() - 3) != "OFF") {
    cursor.fail("not an OFF file (no OFF header)");
  }
  if (!cursor.lineEnded()) {
    if (cursor.token() != "BINARY") cursor.fail("unexpected text after the OFF header");
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

  // The content lines first (cheap: a scan for newlines), then vertices and faces parsed in
  // parallel from them; the first error by line order is the one reported.
  std::vector<std::string_view> lines;
  lines.reserve(static_cast<std::size_t>(num_vertices + num_faces));
  while (static_cast<std::int64_t>(lines.size()) < num_vertices + num_faces) {
    lines.push_back(contentLine(
        cursor, lines.size() < static_cast<std::size_t>(num_vertices) ? "vertices" : "faces"));
  }
  std::vector<double> xyz(3 * static_cast<std::size_t>(num_vertices));
  pcl::PolygonMesh mesh;
  mesh.polygons.resize(static_cast<std::size_t>(num_faces));
  const auto parseLine = [&](std::int64_t i) {
    ByteCursor values = cursor.within(lines[static_cast<std::size_t>(i)]);
    if (i < num_vertices) {
      for (int d = 0; d < 3; ++d) xyz[3 * i + d] = values.readDouble("vertex coordinate");
      return;
    }
    auto& polygon = mesh.polygons[static_cast<std::size_t>(i - num_vertices)];
    const std::int64_t n = values.readInt("face size");
    if (n < 0 || n > static_cast<std::int64_t>(values.remaining())) {
      values.fail("face size " + std::to_string(n) + " does not fit its line");
    }
    polygon.vertices.resize(static_cast<std::size_t>(n));
    for (auto& corner : polygon.vertices) corner = cornerIndex(values.readInt("face index"));
  };
  // The first error by line order is the one reported: each thread's lines are contiguous.
  constexpr std::int64_t kLinesPerThread = 16384;  // small files: no thread started
  parallelForInLoader(num_vertices + num_faces, kLinesPerThread, parseLine);
  mesh.cloud = makeXYZCloud(xyz);
  return mesh;
}

}  // namespace detail
}  // namespace pcl_ddg
