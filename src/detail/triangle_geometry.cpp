#include "detail/triangle_geometry.h"

#include <string>

#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/mesh/vertex_positions.h"

namespace pcl_ddg {
namespace detail {

void requireMatchingPositions(const MeshTopology& topology, const PositionsRef& positions) {
  if (positions.cols() != topology.numVertices()) {
    throw InvalidMeshException("positions have " + std::to_string(positions.cols()) +
                               " columns for a mesh of " + std::to_string(topology.numVertices()) +
                               " vertices");
  }
  requireFinite(positions);
}

}  // namespace detail
}  // namespace pcl_ddg
