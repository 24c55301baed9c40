#pragma once
/** \file
 * What a point cloud holds before any estimator runs on it.
 */
#include <pcl/PCLPointCloud2.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

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

/** The same report built from a cloud's points a piece at a time, for a file read in pieces
 *  (pcl_ddg_info): every point is given twice, to count() and then to compare(), in pieces of any
 *  size. Between the passes it holds a 64-bit hash of each finite point's exact coordinates;
 *  compare() keeps only the points whose hash repeats and counts the equal ones among them, so
 *  that two distinct points whose hashes collide are no duplicate. */
class CloudReportBuilder {
 public:
  /** Room for width x height points' hashes is taken at once. */
  CloudReportBuilder(std::int64_t width, std::int64_t height);
  /** First pass: NaN points, the box, the finite points' hashes. */
  void count(const PositionsRef& piece);
  /** Second pass, the same points again (in any order): the ones whose hash repeats. */
  void compare(const PositionsRef& piece);
  /** The finite points counted so far. */
  std::int64_t finitePoints() const { return report_.points - report_.nan_points; }
  /** The finite points' box so far (empty when none is finite). */
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }
  /** Once, after both passes. */
  CloudReport report();

 private:
  CloudReport report_;
  Eigen::AlignedBox3d bounds_;
  std::vector<std::uint64_t> hashes_;    ///< first pass: one per finite point
  std::vector<std::uint64_t> repeated_;  ///< sorted: the hashes met more than once
  bool comparing_ = false;
  std::vector<std::array<double, 3>> suspects_;  ///< points whose hash repeats
};

}  // namespace pcl_ddg
