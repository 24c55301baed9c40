#pragma once
/** \file
 * Which way an estimated normal points. A plane or quadric fit gives a direction only; the sign
 * comes from a reference:
 *  Viewpoint  towards the sensor: n . (viewpoint - p) >= 0, as pcl::NormalEstimation does
 *             (default viewpoint: the origin).
 *  MeshFaces  agreeing with the mesh's own faces: n . (area-weighted vertex normal) >= 0, so the
 *             result is oriented like the input winding wherever the mesh is consistently
 *             oriented. Points without a usable face normal fall back to the viewpoint.
 *  Up         aerial and terrestrial LiDAR: n . up >= 0 (up: +z unless set; camera-frame
 *             clouds are y-down). A viewpoint far above a survey would do the same, but the
 *             origin or a PCD's VIEWPOINT 0 0 0 lies kilometres to the side of UTM data.
 *  SpanningTree  one consistent side without a single viewpoint (merged, multi-view clouds):
 *             made to agree along a minimum spanning tree of the neighbour graph
 *             (consistent_orientation.h); with a reference (the viewpoint, or up) the reference
 *             decides every point it can and the tree fills in the rest, else each tree is
 *             seeded up at its highest point.
 */
#include <Eigen/Core>

#include "pcl_ddg/mesh/mesh_topology.h"

namespace pcl_ddg {

enum class NormalOrientation { Viewpoint, MeshFaces, SpanningTree, Up };

/** Area-weighted vertex normals (unnormalised) from the triangles whose corners are all finite;
 *  zero where a vertex has none. Accepts NaN positions. */
Eigen::Matrix3Xd meshOrientationNormals(const MeshTopology& topology,
                                        const Eigen::Matrix3Xd& positions);

}  // namespace pcl_ddg
