#pragma once
// Builds the vertex cloud of a text mesh format: x, y, z as float when every coordinate survives
// the round trip through float exactly, as double otherwise (coordinates are never rounded).
#include <pcl/PCLPointCloud2.h>

#include <vector>

namespace pcl_ddg {
namespace detail {

/** xyz holds x0 y0 z0 x1 y1 z1 ... */
pcl::PCLPointCloud2 makeXYZCloud(const std::vector<double>& xyz);

}  // namespace detail
}  // namespace pcl_ddg
