// STL stores every triangle with its own three corners; corners with identical coordinates are
// merged into one vertex (in order of first appearance) so that the result has connectivity.
#include <array>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "byte_cursor.h"
#include "mesh_formats.h"
#include "xyz_cloud.h"

namespace pcl_ddg {
namespace detail {
namespace {

struct CornerHash {
  std::size_t operator()(const std::array<double, 3>& p) const {
    std::size_t h = 0;
    for (double v : p) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, 8);
      h = (h ^ bits) * 0x100000001b3ULL;
    }
    return h;
  }
};

class CornerMerger {
 public:
  pcl::index_t add(const std::array<double, 3>& p) {
    const auto [it, inserted] = index_.emplace(p, static_cast<pcl::index_t>(xyz_.size() / 3));
    if (inserted) xyz_.insert(xyz_.end(), p.begin(), p.end());
    return it->second;
  }
  const std::vector<double>& xyz() const { return xyz_; }

 private:
  std::unordered_map<std::array<double, 3>, pcl::index_t, CornerHash> index_;
  std::vector<double> xyz_;
};

bool isBinarySTL(std::string_view data) {
  if (data.size() < 84) return false;
  std::uint32_t n;
  std::memcpy(&n, data.data() + 80, 4);
  return data.size() == 84 + 50 * static_cast<std::uint64_t>(n);
}

}  // namespace

pcl::PolygonMesh parseSTL(std::string_view data) {
  ByteCursor cursor(data);
  CornerMerger corners;
  pcl::PolygonMesh mesh;
  if (isBinarySTL(data)) {
    cursor.skip(80, "header");
    const auto n = cursor.readBinary<std::uint32_t>(ByteOrder::Little, "triangle count");
    mesh.polygons.resize(n);
    for (auto& polygon : mesh.polygons) {
      cursor.skip(12, "facet normal");
      for (int k = 0; k < 3; ++k) {
        std::array<double, 3> p;
        for (double& v : p) v = cursor.readBinary<float>(ByteOrder::Little, "facet corner");
        polygon.vertices.push_back(corners.add(p));
      }
      cursor.skip(2, "attribute");
    }
  } else {
    if (cursor.token() != "solid") cursor.fail("not an STL file (neither binary nor 'solid')");
    pcl::Vertices polygon;
    bool ended = false;
    for (std::string_view t = cursor.token(); !t.empty(); t = cursor.token()) {
      if (t == "vertex") {
        std::array<double, 3> p;
        for (double& v : p) v = cursor.readDouble("vertex coordinate");
        polygon.vertices.push_back(corners.add(p));
      } else if (t == "endloop") {
        if (polygon.vertices.size() != 3) cursor.fail("STL facet without three vertices");
        mesh.polygons.push_back(std::move(polygon));
        polygon = pcl::Vertices();
      } else if (t == "endsolid") {
        ended = true;
        break;
      }
    }
    if (!ended) cursor.fail("STL file ends without 'endsolid' (truncated?)");
  }
  if (mesh.polygons.empty()) cursor.fail("STL file has no facets");
  mesh.cloud = makeXYZCloud(corners.xyz());
  return mesh;
}

}  // namespace detail
}  // namespace pcl_ddg
