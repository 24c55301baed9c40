// Wavefront OBJ: only geometry is read ("v" and "f"); texture coordinates, normals, groups and
// materials are ignored. Indices are 1-based; negative ones count back from the latest vertex.
#include <vector>

#include "byte_cursor.h"
#include "mesh_formats.h"
#include "xyz_cloud.h"

namespace pcl_ddg {
namespace detail {

pcl::PolygonMesh parseOBJ(std::string_view data) {
  ByteCursor cursor(data);
  std::vector<double> xyz;
  pcl::PolygonMesh mesh;
  bool any_record = false;
  while (!cursor.atEnd()) {
    ByteCursor record = cursor.within(cursor.line());
    const std::string_view keyword = record.token();
    if (keyword.empty() || keyword.front() == '#') continue;
    if (keyword == "v") {
      for (int d = 0; d < 3; ++d) xyz.push_back(record.readDouble("vertex coordinate"));
      any_record = true;
    } else if (keyword == "f") {
      pcl::Vertices polygon;
      const auto vertex_count = static_cast<std::int64_t>(xyz.size() / 3);
      for (std::string_view corner = record.token(); !corner.empty(); corner = record.token()) {
        const std::int64_t index =
            record.parseInt(corner.substr(0, corner.find('/')), "face index");
        // 1-based, or negative relative to the latest vertex.
        const std::int64_t zero_based = index < 0 ? vertex_count + index : index - 1;
        polygon.vertices.push_back(cornerIndex(zero_based));
      }
      mesh.polygons.push_back(std::move(polygon));
      any_record = true;
    } else if (keyword.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_") !=
               std::string_view::npos) {
      record.fail("not an OBJ record: '" + std::string(keyword.substr(0, 40)) + "'");
    }
  }
  if (!any_record) cursor.fail("OBJ file has no vertices");
  mesh.cloud = makeXYZCloud(xyz);
  return mesh;
}

}  // namespace detail
}  // namespace pcl_ddg
