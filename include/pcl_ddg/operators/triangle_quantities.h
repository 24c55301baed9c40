#pragma once
// Per-triangle geometry shared by the operators: area, area vector, corner angles and their
// cotangents. Degenerate triangles (isDegenerateTriangle: zero area by a relative guard) get
// zeros everywhere, so they add nothing to any weight, area, angle sum or normal.
#include <Eigen/Core>
#include <cstdint>

#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

struct TriangleQuantities {
  Eigen::VectorXd areas;        ///< T
  Eigen::Matrix3Xd area_vectors;  ///< (b - a) x (c - a) / 2: normal times area, input winding
  Eigen::Matrix3Xd angles;      ///< (k, t): interior angle at corner k
  Eigen::Matrix3Xd cotangents;  ///< (k, t): cotangent of the angle at corner k
  std::int64_t degenerate_triangles = 0;
};

/** Computes all of the above (OpenMP over triangles). Positions must be finite. */
TriangleQuantities computeTriangleQuantities(const MeshTopology& topology,
                                             const Eigen::Matrix3Xd& positions);

/** Throws InvalidMeshException unless positions has one finite column per topology vertex. */
void requireMatchingPositions(const MeshTopology& topology, const Eigen::Matrix3Xd& positions);

}  // namespace pcl_ddg
