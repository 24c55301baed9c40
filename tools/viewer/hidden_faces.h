#pragma once
// When a mesh may be drawn without its back faces: when no back face can be the first face a line
// of sight meets. Culling them then changes only a few pixels of the outline (where a back face
// sharing an edge with a front face covered a pixel's centre or won its depth test), and it saves
// a software rasteriser (Mesa's llvmpipe, as under Xvfb or without a GPU) a third of every frame.
#include <Eigen/Core>

#include "pcl_ddg/mesh/mesh_topology.h"

class vtkCamera;

namespace pcl_ddg {
namespace viewer {

/** Whether every component of the mesh is closed, consistently oriented and encloses a positive
 *  volume (its faces point outwards). Then a line of sight from outside the solid enters it through
 *  a front face before it meets any back face, unless the surface folds through itself. */
bool facesOutward(const MeshTopology& topology, const Eigen::Matrix3Xd& positions);

/** Whether the box {x0, x1, y0, y1, z0, z1} lies wholly beyond the camera's near clipping plane:
 *  then the camera is outside it and the near plane cuts nothing open. */
bool boxBeyondNearPlane(vtkCamera& camera, const double bounds[6]);

}  // namespace viewer
}  // namespace pcl_ddg
