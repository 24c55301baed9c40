#pragma once
// Which way an estimated normal points. A plane or quadric fit gives a direction only; the sign
// comes from a reference:
//  Viewpoint  towards the sensor: n . (viewpoint - p) >= 0, as pcl::NormalEstimation does
//             (default viewpoint: the origin).
//  MeshFaces  agreeing with the mesh's own faces: n . (area-weighted vertex normal) >= 0, so the
//             result is oriented like the input winding wherever the mesh is consistently
//             oriented. Points without a usable face normal fall back to the viewpoint.
//  SpanningTree  one consistent side without a single viewpoint (merged, multi-view clouds):
//             made to agree along a minimum spanning tree of the neighbour graph
//             (consistent_orientation.h), each tree seeded up at its highest point or facing the
//             viewpoint.
#include <Eigen/Core>

#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

enum class NormalOrientation { Viewpoint, MeshFaces, SpanningTree };

/** Area-weighted vertex normals (unnormalised) from the triangles whose corners are all finite;
 *  zero where a vertex has none. Accepts NaN positions. */
Eigen::Matrix3Xd meshOrientationNormals(const MeshTopology& topology,
                                        const Eigen::Matrix3Xd& positions);

}  // namespace pcl_ddg
