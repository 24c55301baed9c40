#pragma once
/** \file
 * How the mesh functions take vertex positions.
 */
#include <Eigen/Core>

namespace pcl_ddg {

/**
 * Vertex positions as the mesh functions read them: 3 x N doubles, column i the position of vertex
 * i. The Ref binds an Eigen::Matrix3Xd and a view of another owner's memory in the same layout (an
 * Eigen::Map of N x 3 C-order doubles, as a NumPy array holds them) alike, without a copy.
 */
using PositionsRef = Eigen::Ref<const Eigen::Matrix3Xd>;

}  // namespace pcl_ddg
