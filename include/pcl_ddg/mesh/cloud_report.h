#pragma once
/** \file
 * What a point cloud holds before any estimator runs on it.
 */
#include <pcl/PCLPointCloud2.h>

#include <cstdint>
#include <string>

#include "pcl_ddg/mesh/mesh_geometry.h"

namespace pcl_ddg {

struct CloudReport {
  std::int64_t points = 0;
  std::int64_t width = 0;
  std::int64_t height = 0;      ///< > 1 for an organized cloud (image grid)
  std::int64_t nan_points = 0;  ///< points with a NaN or infinite coordinate
  std::int64_t duplicate_points =
      0;  ///< finite points with exactly the coordinates of an earlier one
  BoundingBox bounding_box;

  bool organized() const { return height > 1; }
  std::string toJson() const;
  std::string toText() const;
};

/** Throws InvalidMeshException if the cloud has no x, y, z fields. */
CloudReport makeCloudReport(const pcl::PCLPointCloud2& cloud);

}  // namespace pcl_ddg
