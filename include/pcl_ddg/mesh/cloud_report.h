#pragma once
/** \file
 * What a point cloud holds before any estimator runs on it.
 */
#include <pcl/PCLPointCloud2.h>

#include <cstdint>
#include <string>

#include "pcl_ddg/mesh/mesh_geometry.h"
#include "pcl_ddg/mesh/positions_ref.h"

namespace pcl_ddg {

struct CloudReport {
  std::int64_t points = 0;
  std::int64_t width = 0;
  std::int64_t height = 0;      ///< > 1 for an organized cloud (image grid)
  std::int64_t nan_points = 0;  ///< points with a NaN or infinite coordinate
  std::int64_t duplicate_points =
      0;  ///< finite points with exactly the coordinates of an earlier one
  /** Of the finite points (NaN corners if there is none). */
  BoundingBox bounding_box;

  bool organized() const { return height > 1; }
  std::string toJson() const;
  std::string toText() const;
};

/** The report of cloud (its layout) whose points are at positions, one column per point: the
 *  exact coordinates (MeshFile::positions), so that duplicates and the box are those of the
 *  file's values, not of their float rounding. Throws InvalidMeshException if the counts differ. */
CloudReport makeCloudReport(const pcl::PCLPointCloud2& cloud, const PositionsRef& positions);

}  // namespace pcl_ddg
