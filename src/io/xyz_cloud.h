#pragma once
// Builds the vertex cloud of a text mesh format: x, y, z as float when every coordinate survives
// the round trip through float exactly, as double otherwise (coordinates are never rounded).
#include <pcl/PCLPointCloud2.h>

#include <cstddef>
#include <cstring>
#include <vector>

namespace pcl_ddg {
namespace detail {

/** xyz holds x0 y0 z0 x1 y1 z1 ... */
pcl::PCLPointCloud2 makeXYZCloud(const std::vector<double>& xyz);

/** A cloud of `points` points, x, y, z as FLOAT64, for a parser to fill (setXYZ) and then
 *  narrowXYZCloud: the coordinates parsed straight into the cloud, no second array of them. */
pcl::PCLPointCloud2 doubleXYZCloud(std::size_t points);

/** Coordinate d (0, 1, 2 for x, y, z) of point i of a doubleXYZCloud. */
inline void setXYZ(pcl::PCLPointCloud2& cloud, std::size_t i, int d, double value) {
  std::memcpy(cloud.data.data() + 24 * i + 8 * static_cast<std::size_t>(d), &value, 8);
}

/** A filled doubleXYZCloud made FLOAT32 in place (its memory kept) when every coordinate is a
 *  float's value, and is_dense set. */
void narrowXYZCloud(pcl::PCLPointCloud2& cloud);

}  // namespace detail
}  // namespace pcl_ddg
