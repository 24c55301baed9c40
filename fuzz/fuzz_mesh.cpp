// libFuzzer target for building a mesh from arbitrary arrays: MeshTopology, MeshReport, normals
// and curvatures on any vertex count, coordinates (NaN, infinities, duplicates, huge and tiny
// values) and polygons (any size, out-of-range and repeated indices). Bad input may only end in
// the documented exceptions.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/mesh_report.h"
#include "pcl_ddg/mesh/mesh_topology.h"
#include "pcl_ddg/operators/curvature.h"
#include "pcl_ddg/surface/mesh_normals.h"

namespace {

class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return at_ >= size_; }
  std::uint8_t next() { return at_ < size_ ? data_[at_++] : 0; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

// Mostly small lattice coordinates (so that faces share edges and come out degenerate or
// duplicate), sometimes a special value.
double coordinate(Bytes& bytes) {
  const std::uint8_t b = bytes.next();
  switch (b) {
    case 250:
      return std::numeric_limits<double>::quiet_NaN();
    case 251:
      return std::numeric_limits<double>::infinity();
    case 252:
      return 1e300;
    case 253:
      return 1e-300;
    case 254:
      return 1e5 + 1e-9;
    default:
      return static_cast<double>(b % 8) - 4.0;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes bytes(data, size);
  const int num_vertices = bytes.next() % 64;
  Eigen::Matrix3Xd positions(3, num_vertices);
  for (int v = 0; v < num_vertices; ++v) {
    for (int d = 0; d < 3; ++d) positions(d, v) = coordinate(bytes);
  }
  std::vector<pcl::Vertices> polygons;
  while (!bytes.empty()) {
    pcl::Vertices polygon;
    const int corners = bytes.next() % 8;
    for (int k = 0; k < corners; ++k) {
      const std::uint8_t b = bytes.next();
      polygon.vertices.push_back(b == 255 ? -1 : b % 72);  // some beyond num_vertices
    }
    polygons.push_back(polygon);
  }
  try {
    const pcl_ddg::MeshTopology topology(num_vertices, polygons,
                                         pcl_ddg::OutOfRangeFacePolicy::Drop);
    pcl_ddg::makeMeshReport(topology, positions);
    if (!positions.allFinite()) return 0;  // the operators refuse those (tested elsewhere)
    for (auto weighting :
         {pcl_ddg::NormalWeighting::Uniform, pcl_ddg::NormalWeighting::Area,
          pcl_ddg::NormalWeighting::Angle, pcl_ddg::NormalWeighting::MeanCurvature}) {
      pcl_ddg::MeshNormalOptions options;
      options.weighting = weighting;
      const pcl_ddg::MeshNormals n = pcl_ddg::computeMeshNormals(topology, positions, options);
      // The contract: a unit normal where valid, NaN (never a silent bad number) elsewhere.
      for (int v = 0; v < num_vertices; ++v) {
        const double norm = n.normals.col(v).norm();
        if (n.valid[v] ? !(std::abs(norm - 1.0) < 1e-9) : !std::isnan(norm)) __builtin_trap();
      }
    }
    const pcl_ddg::VertexCurvatures c = pcl_ddg::computeCurvatures(topology, positions);
    for (int v = 0; v < num_vertices; ++v) {
      if (c.valid[v] &&
          !std::isfinite(c.mean_curvature[v] + c.gauss_curvature[v] + c.k1[v] + c.k2[v]))
        __builtin_trap();
    }
  } catch (const pcl_ddg::InvalidMeshException&) {
  } catch (const pcl::BadArgumentException&) {
  }
  return 0;
}
