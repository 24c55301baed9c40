// Object File Format (Geomview): "OFF" header, counts, vertices, faces. Colour and normal variants
// (COFF, NOFF, CNOFF) carry extra values per line, which are ignored; "OFF BINARY" is big-endian.
#include <vector>

#include "byte_cursor.h"
#include "formats.h"
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

pcl::PolygonMesh parseBinaryOFF(ByteCursor& cursor) {
  const auto read_count = [&](const char* what) {
    const std::int32_t n = cursor.readBinary<std::int32_t>(ByteOrder::Big, what);
    if (n < 0) cursor.fail(std::string("negative ") + what);
    return n;
  };
  const std::int32_t num_vertices = read_count("vertex count");
  const std::int32_t num_faces = read_count("face count");
  read_count("edge count");
  if (static_cast<std::size_t>(num_vertices) * 12 > cursor.remaining()) {
    cursor.fail("binary OFF is shorter than its vertex count says");
  }
  std::vector<double> xyz(3 * static_cast<std::size_t>(num_vertices));
  for (double& v : xyz) v = cursor.readBinary<float>(ByteOrder::Big, "vertex");
  pcl::PolygonMesh mesh;
  mesh.cloud = makeXYZCloud(xyz);
  mesh.polygons.resize(num_faces);
  for (auto& polygon : mesh.polygons) {
    const std::int32_t n = read_count("face size");
    for (std::int32_t k = 0; k < n; ++k) {
      polygon.vertices.push_back(
          cornerIndex(cursor.readBinary<std::int32_t>(ByteOrder::Big, "face")));
    }
    const std::int32_t colour_values = read_count("face colour count");
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
  if (num_vertices > static_cast<std::int64_t>(data.size())) {
    cursor.fail("vertex count larger than the file");
  }

  std::vector<double> xyz(3 * static_cast<std::size_t>(num_vertices));
  for (std::int64_t i = 0; i < num_vertices; ++i) {
    ByteCursor values = cursor.within(contentLine(cursor, "vertices"));
    for (int d = 0; d < 3; ++d) xyz[3 * i + d] = values.readDouble("vertex coordinate");
  }
  pcl::PolygonMesh mesh;
  mesh.cloud = makeXYZCloud(xyz);
  mesh.polygons.resize(static_cast<std::size_t>(num_faces));
  for (auto& polygon : mesh.polygons) {
    ByteCursor values = cursor.within(contentLine(cursor, "faces"));
    const std::int64_t n = values.readInt("face size");
    if (n < 0) cursor.fail("negative face size");
    polygon.vertices.reserve(static_cast<std::size_t>(n));
    for (std::int64_t k = 0; k < n; ++k) {
      polygon.vertices.push_back(cornerIndex(values.readInt("face index")));
    }
  }
  return mesh;
}

}  // namespace detail
}  // namespace pcl_ddg
